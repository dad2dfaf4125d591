# SPDX-License-Identifier: Apache-2.0
"""Progress of a long call: `progress=True` shows a bar per stage ("G-buffer", "raytraced",
"bake grid.obj") with tqdm when it is installed, and otherwise a line on stderr every few seconds;
a callable gets (stage, done, total) itself. The library calls it on the calling thread, at most
every 100 ms while a stage reports progress and once when the call ends (python/src/call.h)."""

import sys
import time


class _Lines:
    """One line per stage on stderr at most every `seconds`: "ao: raytraced 42%"."""

    def __init__(self, stream=None, seconds=5.0):
        self.stream = stream or sys.stderr
        self.seconds = seconds
        self.stage = None
        self.last = 0.0

    def __call__(self, stage, done, total):
        now = time.monotonic()
        if stage == self.stage and now - self.last < self.seconds and done < total:
            return
        self.stage, self.last = stage, now
        percent = f"{100 * done / total:.0f}%" if total else "..."
        print(f"ao: {stage} {percent}", file=self.stream, flush=True)


class _Bars:
    """A tqdm bar per stage, closed when the next stage starts or the call ends."""

    def __init__(self, tqdm):
        self.tqdm = tqdm
        self.stage = None
        self.bar = None

    def __call__(self, stage, done, total):
        if stage != self.stage:
            self.close()
            self.stage = stage
            self.bar = self.tqdm(total=total or None, desc=stage, leave=False)
        if total and self.bar.total != total:
            self.bar.total = total
        self.bar.update(done - self.bar.n)

    def close(self):
        if self.bar is not None:
            self.bar.close()
            self.bar = None


def reporter(progress):
    """What the library is given for the `progress` argument: None, or a callable(stage, done,
    total); and a function that ends the display when the call returns (or fails)."""
    if progress is None or progress is False:
        return None, lambda: None
    if progress is not True:
        return progress, lambda: None
    try:
        from tqdm.auto import tqdm  # type: ignore[import]  # optional, without stubs
    except ImportError:
        return _Lines(), lambda: None
    bars = _Bars(tqdm)
    return bars, bars.close
