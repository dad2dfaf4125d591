// SPDX-License-Identifier: Apache-2.0
#include "ao/jobs/provenance.h"

#include <cctype>
#include <cstdio>
#include <fstream>
#include <memory>

#include <openssl/evp.h>
#include <sys/stat.h>

#include "ao/core/error.h"
#include "ao/io/atomic_file.h"
#include "ao/io/output_set.h"
#include "ao/scene/mesh.h"
#include "ao/simd/target.h"
#include "ao/version.h"

namespace ao {

namespace fs = std::filesystem;

nlohmann::json build_info() { return {{"version", AO_VERSION_STRING}, {"simd_target", simd_target()}}; }

namespace {

// SHA-256 through OpenSSL's EVP interface, fed piece by piece.
class Sha256 {
 public:
  explicit Sha256(const std::string& what) : ctx_(EVP_MD_CTX_new(), EVP_MD_CTX_free) {
    if (!ctx_ || EVP_DigestInit_ex(ctx_.get(), EVP_sha256(), nullptr) != 1) throw SystemError(what + ": SHA-256 is not available (OpenSSL)");
  }
  void add(const void* data, std::size_t bytes) {
    if (bytes) EVP_DigestUpdate(ctx_.get(), data, bytes);
  }
  template <class T>
  void add(const std::vector<T>& v) {
    add(static_cast<const void*>(v.data()), v.size() * sizeof(T));
  }
  std::string hex() {
    unsigned char digest[EVP_MAX_MD_SIZE];
    unsigned int size = 0;
    EVP_DigestFinal_ex(ctx_.get(), digest, &size);
    std::string out;
    for (unsigned int i = 0; i < size; ++i) {
      char pair[3];
      std::snprintf(pair, sizeof pair, "%02x", digest[i]);
      out += pair;
    }
    return out;
  }

 private:
  std::unique_ptr<EVP_MD_CTX, decltype(&EVP_MD_CTX_free)> ctx_;
};

}  // namespace

std::string file_sha256(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw SystemError(path.string() + ": cannot read it to hash its contents");
  Sha256 sha(path.string());
  std::vector<char> buffer(1 << 20);
  while (in) {
    in.read(buffer.data(), static_cast<std::streamsize>(buffer.size()));
    sha.add(buffer.data(), static_cast<std::size_t>(in.gcount()));
  }
  if (in.bad()) throw SystemError(path.string() + ": cannot read it to hash its contents");
  return sha.hex();
}

std::string scene_sha256(const Scene& scene) {
  Sha256 sha(scene.name);
  for (const Mesh& m : scene.meshes) {
    const std::uint64_t sizes[] = {m.positions.size(), m.normals.size(), m.uvs.size(), m.indices.size()};
    sha.add(sizes, sizeof sizes);
    sha.add(m.positions);
    sha.add(m.normals);
    sha.add(m.uvs);
    sha.add(m.indices);
    sha.add(&m.albedo, sizeof m.albedo);
  }
  for (const Instance& i : scene.instances) {
    sha.add(&i.mesh, sizeof i.mesh);
    sha.add(&i.object_to_world, sizeof i.object_to_world);
  }
  return sha.hex();
}

std::vector<fs::path> files_read_by(const fs::path& mesh) {
  std::vector<fs::path> files = {mesh};
  std::string ext = mesh.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (ext != ".gltf") return files;
  std::ifstream in(mesh, std::ios::binary);
  const nlohmann::json doc = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
  if (!doc.is_object() || !doc.contains("buffers") || !doc["buffers"].is_array()) return files;
  for (const nlohmann::json& b : doc["buffers"]) {
    if (!b.is_object() || !b.contains("uri") || !b["uri"].is_string()) continue;
    const std::string uri = b["uri"].get<std::string>();
    if (uri.rfind("data:", 0) == 0 || uri.find("://") != std::string::npos) continue;
    const fs::path f = mesh.parent_path() / uri;
    std::error_code ec;
    if (fs::is_regular_file(f, ec)) files.push_back(f);  // a missing buffer is the loader's to report
  }
  return files;
}

fs::path provenance_path(const fs::path& output) { return output.string() + ".ao.json"; }

nlohmann::json provenance_record(std::string_view job, const std::vector<ProvenanceInput>& inputs, nlohmann::json settings, bool hash_inputs) {
  nlohmann::json in = nlohmann::json::array();
  for (const ProvenanceInput& i : inputs) {
    if (!hash_inputs) {
      in.push_back({{"role", i.role}, {"path", i.path.string()}});
      continue;
    }
    struct stat st {};
    if (::stat(i.path.c_str(), &st) != 0) throw SystemError(i.path.string() + ": cannot read its size to record it");
    const std::int64_t mtime_ns = static_cast<std::int64_t>(st.st_mtim.tv_sec) * 1'000'000'000 + st.st_mtim.tv_nsec;
    in.push_back({{"role", i.role}, {"path", i.path.string()}, {"bytes", static_cast<std::uint64_t>(st.st_size)}, {"mtime_ns", mtime_ns},
                  {"sha256", file_sha256(i.path)}});
  }
  return {{"ao", build_info()}, {"job", std::string(job)}, {"inputs", in}, {"settings", std::move(settings)}};
}

void declare_provenance(OutputSet& set, const std::vector<fs::path>& outputs, const std::string& what) {
  for (const fs::path& o : outputs) set.add_output(provenance_path(o), what);
}

void stage_provenance(OutputSet& outputs, const nlohmann::json& record) {
  const std::vector<fs::path> written = outputs.written();
  nlohmann::json names = nlohmann::json::array();
  for (const fs::path& o : written) names.push_back(o.filename().string());
  for (const fs::path& o : written) {
    const fs::path staged = outputs.staged(o);
    nlohmann::json r = record;
    std::error_code ec;
    const auto bytes = fs::file_size(staged, ec);
    if (ec) throw SystemError(o.string() + ": cannot read the staged output's size: " + ec.message());
    r["output"] = {{"file", o.filename().string()}, {"bytes", bytes}, {"sha256", file_sha256(staged)}};
    r["outputs"] = names;
    const std::string text = r.dump(1) + "\n";
    const fs::path path = provenance_path(o);
    outputs.write(path, [&] {
      write_file_atomically(path, [&](const fs::path& temp) {
        std::FILE* f = std::fopen(temp.c_str(), "wb");
        const bool ok = f && std::fwrite(text.data(), 1, text.size(), f) == text.size();
        if ((f && std::fclose(f) != 0) || !ok) throw SystemError(path.string() + ": cannot write");
      });
    });
  }
}

}  // namespace ao
