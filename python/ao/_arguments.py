# SPDX-License-Identifier: Apache-2.0
"""The checks of ao's keyword arguments before anything reaches the library: a value of the wrong
type raises TypeError, a NaN, an infinity or an integer too large for the library's field raises
ao.InputError (a ValueError), each naming the argument as the caller wrote it. Ranges that the
library knows (spp in [1, 1048576], ...) are left to it: its message names the same argument
(python/src/field_names.cpp), so the valid range is written once."""

import math
import numbers
import os

from ._ao import InputError, did_you_mean

_INT32 = (-2 ** 31, 2 ** 31 - 1)
_UINT32 = (0, 2 ** 32 - 1)


def _shown(value):
    """The value for a message: its type, and its repr when that is short."""
    text = repr(value) if isinstance(value, (str, bytes, numbers.Number)) else ""
    if len(text) > 40:
        text = text[:37] + "..."
    return f"{type(value).__name__} {text}".rstrip()


def integer(name, value, *, bounds=_INT32, optional=False):
    """`value` as an int: an integer (Python's, numpy's) within `bounds`; not a bool, a float or a str."""
    if value is None and optional:
        return None
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise TypeError(f"{name}: expected an integer, got {_shown(value)}")
    value = int(value)
    if not bounds[0] <= value <= bounds[1]:
        raise InputError(f"{name}: {value} is out of range [{bounds[0]}, {bounds[1]}]")
    return value


def seed(name, value):
    """A seed of the sample sets: an integer in [0, 4294967295]."""
    return integer(name, value, bounds=_UINT32)


def number(name, value, *, optional=False):
    """`value` as a finite float: an int or a float (Python's, numpy's); not a bool or a str."""
    if value is None and optional:
        return None
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(f"{name}: expected a number, got {_shown(value)}")
    value = float(value)
    if not math.isfinite(value):
        raise InputError(f"{name}: expected a finite number, got {value}")
    return value


def text(name, value, *, optional=False):
    """`value` as a str."""
    if value is None and optional:
        return None
    if not isinstance(value, str):
        raise TypeError(f"{name}: expected a string, got {_shown(value)}")
    return value


def flag(name, value):
    """`value` as a bool: True or False (numpy's too), not 0, 1 or a string."""
    if isinstance(value, bool):
        return value
    if type(value).__name__ == "bool_":  # numpy.bool_
        return bool(value)
    raise TypeError(f"{name}: expected True or False, got {_shown(value)}")


def path(name, value, *, optional=True):
    """`value` as a file name: a str or an os.PathLike (bytes are not accepted)."""
    if value is None and optional:
        return None
    if isinstance(value, os.PathLike):
        value = os.fspath(value)
    if not isinstance(value, str):
        raise TypeError(f"{name}: expected a file name (str or os.PathLike), got {_shown(value)}")
    if not value:
        raise InputError(f"{name}: the file name is empty")
    return value


def vector3(name, value, *, optional=True):
    """`value` as three finite floats (a list, tuple or numpy array of 3 numbers)."""
    if value is None and optional:
        return None
    if isinstance(value, (str, bytes)) or not hasattr(value, "__len__") or not hasattr(value, "__iter__"):
        raise TypeError(f"{name}: expected three numbers x, y, z, got {_shown(value)}")
    items = list(value)
    if len(items) != 3:
        raise InputError(f"{name}: expected three numbers x, y, z, got {len(items)} values")
    return [number(f"{name}[{k}]", v) for k, v in enumerate(items)]


def one_of(name, value, choices, *, optional=False):
    """`value` as one of the strings `choices`."""
    value = text(name, value, optional=optional)
    if value is not None and value not in choices:
        raise InputError(f"{name}: expected one of {', '.join(choices)}, got {value!r}{did_you_mean(value, list(choices))}")
    return value


def progress(name, value):
    """None, True (a bar, ao._progress) or a callable taking (stage, done, total)."""
    if value is None or value is False or value is True or callable(value):
        return value
    raise TypeError(f"{name}: expected None, True or a callable(stage, done, total), got {_shown(value)}")
