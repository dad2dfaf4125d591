// SPDX-License-Identifier: Apache-2.0
#include "ao/io/asset_path.h"

#include <cctype>
#include <system_error>

#include "ao/core/error.h"
#include "ao/io/io_error_internal.h"

namespace ao {

namespace fs = std::filesystem;

namespace {

/// Text of a reference for a message: printable and short, whatever the file holds.
std::string printable(std::string_view s) { return io_detail::printable(s, 80); }

}  // namespace

std::string percent_decode(std::string_view s) {
  std::string out;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '%' && i + 2 < s.size() && std::isxdigit(static_cast<unsigned char>(s[i + 1])) && std::isxdigit(static_cast<unsigned char>(s[i + 2]))) {
      out += static_cast<char>(std::stoi(std::string(s.substr(i + 1, 2)), nullptr, 16));
      i += 2;
    } else {
      out += s[i];
    }
  }
  return out;
}

fs::path resolved_path(const fs::path& p) {
  std::error_code ec;
  fs::path abs = fs::absolute(p, ec);
  if (ec) abs = p;
  const fs::path r = fs::weakly_canonical(abs, ec);
  return ec ? abs.lexically_normal() : r;
}

fs::path asset_folder(const fs::path& model, const fs::path& root) {
  if (!root.empty()) return resolved_path(root);
  const fs::path abs = fs::absolute(model);
  return resolved_path(abs.parent_path());
}

bool inside_folder(const fs::path& file, const fs::path& folder) {
  if (folder.empty()) return false;
  const fs::path rel = resolved_path(file).lexically_relative(folder);
  return !rel.empty() && *rel.begin() != "..";
}

fs::path resolve_asset_reference(const fs::path& model, const fs::path& folder, std::string_view reference, const std::string& what) {
  const fs::path file = fs::absolute(model).parent_path() / fs::path(std::string(reference));
  if (reference.empty() || !inside_folder(file, folder))
    throw InputError(model.string() + ": " + what + " '" + printable(reference) + "' lies outside the asset's folder '" + folder.string() +
                     "'; an asset may reference files only in its own folder or below it");
  return file;
}

}  // namespace ao
