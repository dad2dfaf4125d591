#include "ao/io/output_set.h"

#include <system_error>
#include <utility>

#include "ao/core/error.h"

namespace ao {

namespace fs = std::filesystem;

namespace {

fs::path resolve(const fs::path& p) {
  std::error_code ec;
  fs::path abs = fs::absolute(p, ec);
  if (ec) abs = p;
  fs::path r = fs::weakly_canonical(abs, ec);
  return ec ? abs.lexically_normal() : r;
}

// The same file: the same path once resolved, or (when both exist) the same inode, which also
// catches hard links and bind mounts.
bool same_file(const fs::path& a_resolved, const fs::path& b_resolved) {
  if (a_resolved == b_resolved) return true;
  std::error_code ec;
  const bool equal = fs::equivalent(a_resolved, b_resolved, ec);
  return !ec && equal;
}

fs::path parent_of(const fs::path& resolved) { return resolved.has_parent_path() ? resolved.parent_path() : fs::path("."); }

}  // namespace

OutputSet::~OutputSet() {
  std::error_code ec;
  if (!committed_)
    for (const Staged& s : staged_) fs::remove(s.temp, ec);
  staged_.clear();  // unregisters the temporary files before their folders
  if (!committed_)
    for (auto it = directories_.rbegin(); it != directories_.rend(); ++it)
      if (it->created) fs::remove(it->path, ec);  // only if empty: never a user's file
}

OutputSet::Named OutputSet::name(const fs::path& path, std::string what) const { return {path, resolve(path), std::move(what)}; }

const OutputSet::Directory* OutputSet::directory_for(const fs::path& resolved_parent) const {
  for (const Directory& d : directories_)
    if (resolve(d.path) == resolved_parent) return &d;
  return nullptr;
}

void OutputSet::add_input(const fs::path& path, std::string what) {
  std::error_code ec;
  if (path.empty() || !fs::exists(path, ec)) return;
  Named in = name(path, std::move(what));
  for (const Named& out : outputs_)
    if (same_file(out.resolved, in.resolved))
      throw InputError(out.path.string() + ": the output of " + out.what + " is the input of " + in.what + "; give the output another name");
  inputs_.push_back(std::move(in));
}

void OutputSet::add_output(const fs::path& path, std::string what) {
  if (path.empty() || !path.has_filename()) throw InputError(what + ": '" + path.string() + "' names no file");
  Named out = name(path, std::move(what));
  for (const Named& in : inputs_)
    if (same_file(out.resolved, in.resolved))
      throw InputError(path.string() + ": the output of " + out.what + " is the input of " + in.what + "; give the output another name");
  for (const Named& other : outputs_)
    if (same_file(out.resolved, other.resolved)) {
      if (other.what == out.what) return;
      throw InputError(path.string() + ": named as the output of both " + other.what + " and " + out.what + "; give each output its own name");
    }
  std::error_code ec;
  if (fs::is_directory(out.resolved, ec)) throw InputError(path.string() + ": " + out.what + " names a directory, not a file");
  const fs::path dir = parent_of(out.resolved);
  if (!directory_for(dir)) {
    if (!fs::exists(dir, ec)) throw InputError(path.string() + ": folder '" + dir.string() + "' does not exist");
    if (!fs::is_directory(dir, ec)) throw InputError(path.string() + ": '" + dir.string() + "' is not a directory");
  }
  outputs_.push_back(std::move(out));
}

void OutputSet::add_directory(const fs::path& dir, std::string what) {
  std::error_code ec;
  const fs::path resolved = resolve(dir);
  if (directory_for(resolved)) return;
  Directory d;
  d.path = resolved;
  if (fs::exists(resolved, ec)) {
    if (!fs::is_directory(resolved, ec)) throw InputError(dir.string() + ": " + what + " exists and is not a directory");
  } else {
    const fs::path parent = parent_of(resolved);
    if (!fs::is_directory(parent, ec)) throw InputError(dir.string() + ": " + what + ": the parent folder '" + parent.string() + "' does not exist");
    d.create = true;
  }
  for (const Named& in : inputs_)
    if (same_file(resolved, in.resolved)) throw InputError(dir.string() + ": " + what + " is the input of " + in.what);
  directories_.push_back(std::move(d));
}

void OutputSet::write(const fs::path& path, const std::function<void()>& write, std::string what) {
  const fs::path resolved = resolve(path);
  bool declared = false;
  for (const Named& out : outputs_) declared = declared || out.resolved == resolved;
  if (!declared) add_output(path, std::move(what));
  for (Directory& d : directories_)
    if (d.create && !d.created && d.path == parent_of(resolved)) {
      // Registered before it exists, so that a signal after the mkdir finds it.
      d.registration = TemporaryRegistration(d.path, /*directory=*/true);
      std::error_code ec;
      if (!fs::create_directory(d.path, ec) && ec) throw SystemError(d.path.string() + ": cannot create the folder: " + ec.message());
      d.created = true;
    }
  const detail::DeferredRenames defer([this](const fs::path& temp, const fs::path& destination, TemporaryRegistration registration) {
    for (Staged& s : staged_)
      if (s.destination == destination) {  // written twice in one run: the later content wins
        std::error_code ec;
        fs::remove(s.temp, ec);
        s.temp = temp;
        s.registration = std::move(registration);
        return;
      }
    staged_.push_back({temp, destination, std::move(registration)});
  });
  write();
}

fs::path OutputSet::staged(const fs::path& path) const {
  const fs::path resolved = resolve(path);
  for (const Staged& s : staged_)
    if (resolve(s.destination) == resolved) return s.temp;
  throw InputError(path.string() + ": nothing was written for this output yet");
}

void OutputSet::commit() {
  for (Staged& s : staged_) {
    std::error_code ec;
    fs::rename(s.temp, s.destination, ec);
    if (ec) throw SystemError(s.destination.string() + ": cannot rename the temporary file into place: " + ec.message());
    s.registration = TemporaryRegistration();
  }
  for (Directory& d : directories_) d.registration = TemporaryRegistration();
  committed_ = true;
}

std::vector<fs::path> OutputSet::outputs() const {
  std::vector<fs::path> paths;
  for (const Named& out : outputs_) paths.push_back(out.path);
  return paths;
}

}  // namespace ao
