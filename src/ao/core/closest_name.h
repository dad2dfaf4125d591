// SPDX-License-Identifier: Apache-2.0
// The known name closest to a mistyped one, for the "did you mean" of every error that refuses a
// name: commands and options, methods, parameters and their enum values, scenes, formats.
#pragma once

#include <cstddef>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json_fwd.hpp>

namespace ao {

/// Edits between `a` and `b` (optimal string alignment): the fewest single-character insertions,
/// deletions, substitutions and swaps of two neighbours that turn one into the other, ignoring
/// ASCII case ("gtoa" is 1 from "gtao", "raytrace" 1 from "raytraced").
std::size_t edit_distance(std::string_view a, std::string_view b);

/// The candidate closest to `typed` when close enough to be a typo: at most max(1, size / 3) edits
/// away, size being `typed`'s length; the first of equally close ones; empty when none is.
std::string closest_name(std::string_view typed, std::span<const std::string> candidates);

/// "; did you mean 'x'?" naming closest_name(typed, candidates), or "" when none is close: the
/// suffix every refusal of a name ends with.
std::string did_you_mean(std::string_view typed, std::span<const std::string> candidates);

/// did_you_mean over the names of a list written "a, b, c" (the form errors show them in).
std::string did_you_mean(std::string_view typed, std::string_view listed);

/// The keys of a JSON object in its order (none for another value): the names a refusal of an
/// unknown key lists and suggests from.
std::vector<std::string> key_names(const nlohmann::json& object);

}  // namespace ao
