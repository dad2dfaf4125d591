// SPDX-License-Identifier: Apache-2.0
#include "ao/core/closest_name.h"

#include <algorithm>
#include <cctype>
#include <vector>

#include <nlohmann/json.hpp>

namespace ao {

namespace {

char folded(char c) { return static_cast<char>(std::tolower(static_cast<unsigned char>(c))); }

}  // namespace

std::size_t edit_distance(std::string_view a, std::string_view b) {
  // d[i][j]: edits between a's first i and b's first j characters, three rows kept (a swap looks
  // two rows back).
  const std::size_t n = b.size();
  std::vector<std::size_t> before(n + 1), previous(n + 1), row(n + 1);
  for (std::size_t j = 0; j <= n; ++j) previous[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    row[0] = i;
    for (std::size_t j = 1; j <= n; ++j) {
      const bool same = folded(a[i - 1]) == folded(b[j - 1]);
      row[j] = std::min({previous[j] + 1, row[j - 1] + 1, previous[j - 1] + (same ? 0 : 1)});
      if (i > 1 && j > 1 && folded(a[i - 1]) == folded(b[j - 2]) && folded(a[i - 2]) == folded(b[j - 1]))
        row[j] = std::min(row[j], before[j - 2] + 1);
    }
    std::swap(before, previous);
    std::swap(previous, row);
  }
  return previous[n];
}

std::string closest_name(std::string_view typed, std::span<const std::string> candidates) {
  std::string best;
  std::size_t best_distance = std::max<std::size_t>(1, typed.size() / 3) + 1;
  for (const std::string& c : candidates) {
    const std::size_t d = edit_distance(typed, c);
    if (d < best_distance) best_distance = d, best = c;
  }
  return best;
}

std::string did_you_mean(std::string_view typed, std::span<const std::string> candidates) {
  const std::string near = closest_name(typed, candidates);
  return near.empty() ? "" : "; did you mean '" + near + "'?";
}

std::string did_you_mean(std::string_view typed, std::string_view listed) {
  std::vector<std::string> names;
  while (!listed.empty()) {
    const std::size_t comma = listed.find(',');
    std::string_view name = listed.substr(0, comma);
    while (!name.empty() && name.front() == ' ') name.remove_prefix(1);
    while (!name.empty() && name.back() == ' ') name.remove_suffix(1);
    if (!name.empty()) names.emplace_back(name);
    listed = comma == std::string_view::npos ? std::string_view() : listed.substr(comma + 1);
  }
  return did_you_mean(typed, names);
}

std::vector<std::string> key_names(const nlohmann::json& object) {
  std::vector<std::string> names;
  if (object.is_object())
    for (const auto& [k, v] : object.items()) names.push_back(k);
  return names;
}

}  // namespace ao
