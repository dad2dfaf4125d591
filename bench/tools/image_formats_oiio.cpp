// SPDX-License-Identifier: Apache-2.0
// The measurement behind docs/bake.md, "Image formats": ao's own writers (libpng, libtiff,
// libjpeg, a hand-written TGA) against OpenImageIO 2.4 for the map formats of `ao bake`, and both
// readers on damaged files. Built only with -DAO_OIIO_COMPARE=ON (OpenImageIO is not a dependency
// of ao; this tool exists to justify that).
//
//   image_formats_oiio [size] [repetitions]     (default 2048 5)
//
// Speed: a size x size single-channel float map (a smooth falloff with per-texel noise, like a
// baked AO map) written to each format by each library, alternating ao / OIIO, median wall time
// of the repetitions; file sizes. Robustness: every file is damaged (truncated at 1/8 .. 7/8 of its
// length; 64 single bytes overwritten at seeded random offsets) and read by OIIO and, for the formats
// ao reads (PNG, EXR), by ao, each read in a process of its own so a crash or hang is counted, not fatal.
#include <OpenImageIO/imageio.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include "ao/core/error.h"
#include "ao/io/image_io.h"

namespace fs = std::filesystem;

namespace {

struct Format {
  const char* name;
  const char* ext;
  int bits;
};
const Format kFormats[] = {{"PNG 8", ".png", 8}, {"PNG 16", ".png", 16}, {"TIFF 8", ".tif", 8}, {"TIFF 16", ".tif", 16},
                           {"TGA 8", ".tga", 8}, {"JPEG q95", ".jpg", 8},  {"EXR float", ".exr", 32}};

ao::Image<float> test_map(int n) {
  ao::Image<float> im(n, n);
  std::mt19937 rng(1);
  std::normal_distribution<float> noise(0.0f, 0.02f);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const float dx = (x + 0.5f) / n - 0.5f, dy = (y + 0.5f) / n - 0.5f;
      im(x, y) = std::clamp(1.0f - 1.4f * std::sqrt(dx * dx + dy * dy) + noise(rng), 0.0f, 1.0f);
    }
  return im;
}

double now_ms() { return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

void write_ao(const fs::path& p, const ao::Image<float>& im, const Format& f) { ao::write_image(p, im, {.png_bits = f.bits == 16 ? 16 : 8, .jpeg_quality = 95}); }

bool write_oiio(const fs::path& p, const ao::Image<float>& im, const Format& f) {
  auto out = OIIO::ImageOutput::create(p.string());
  if (!out) return false;
  const OIIO::TypeDesc type = f.bits == 32 ? OIIO::TypeDesc::FLOAT : f.bits == 16 ? OIIO::TypeDesc::UINT16 : OIIO::TypeDesc::UINT8;
  OIIO::ImageSpec spec(im.width(), im.height(), 1, type);
  if (std::string(f.ext) == ".jpg") spec.attribute("Compression", "jpeg:95");
  if (std::string(f.ext) == ".tif") spec.attribute("Compression", "zip");
  if (std::string(f.ext) == ".exr") spec.attribute("Compression", "zip");
  if (!out->open(p.string(), spec)) return false;
  const bool ok = out->write_image(OIIO::TypeDesc::FLOAT, im.data());
  return out->close() && ok;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

std::string read_all(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

enum class Outcome { Read, Error, Crash, Hang };

// Reads `file` with `reader` ("oiio" or "ao") in a fresh process (this program with --read): 0 =
// read, 1 = a reported error, a signal = crash, more than 10 s = hang. A fresh process, not a bare
// fork, because a fork of a process whose libraries already started threads may deadlock in them.
Outcome in_child(const char* self, const char* reader, const fs::path& file) {
  std::fflush(stdout);
  const pid_t pid = fork();
  if (pid == 0) {
    alarm(10);
    execl(self, self, "--read", reader, file.c_str(), static_cast<char*>(nullptr));
    std::_Exit(127);
  }
  int status = 0;
  waitpid(pid, &status, 0);
  if (WIFSIGNALED(status)) return WTERMSIG(status) == SIGALRM ? Outcome::Hang : Outcome::Crash;
  return WEXITSTATUS(status) == 0 ? Outcome::Read : Outcome::Error;
}

bool read_oiio(const fs::path& p) {
  auto in = OIIO::ImageInput::open(p.string());
  if (!in) return false;
  const OIIO::ImageSpec& s = in->spec();
  std::vector<float> buf(static_cast<std::size_t>(s.width) * s.height * s.nchannels);
  const bool ok = in->read_image(0, 0, 0, -1, OIIO::TypeDesc::FLOAT, buf.data());
  in->close();
  return ok;
}

bool read_ao(const fs::path& p) {
  try {
    ao::read_image(p);
    return true;
  } catch (const ao::InputError&) {
    return false;
  } catch (const ao::SystemError&) {
    return false;
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 4 && std::string(argv[1]) == "--read") return (std::string(argv[2]) == "oiio" ? read_oiio(argv[3]) : read_ao(argv[3])) ? 0 : 1;
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // lines appear as they are measured, and forked children inherit no buffered output
  const int n = argc > 1 ? std::atoi(argv[1]) : 2048;
  const int reps = argc > 2 ? std::atoi(argv[2]) : 5;
  const fs::path dir = fs::temp_directory_path() / ("ao-image-formats-" + std::to_string(getpid()));
  fs::create_directories(dir);
  const ao::Image<float> im = test_map(n);
  std::printf("%dx%d single-channel map, median of %d writes, alternating ao / OIIO\n\n", n, n, reps);
  std::printf("| format | ao ms | OIIO ms | OIIO / ao | ao bytes | OIIO bytes |\n|---|---|---|---|---|---|\n");
  for (const Format& f : kFormats) {
    const fs::path pa = dir / (std::string("ao") + f.ext), po = dir / (std::string("oiio") + f.ext);
    std::vector<double> ta, to;
    for (int r = 0; r < reps; ++r) {
      double t0 = now_ms();
      write_ao(pa, im, f);
      ta.push_back(now_ms() - t0);
      t0 = now_ms();
      if (!write_oiio(po, im, f)) {
        std::printf("OIIO cannot write %s: %s\n", f.name, OIIO::geterror().c_str());
        return 1;
      }
      to.push_back(now_ms() - t0);
    }
    std::printf("| %s | %.1f | %.1f | %.2f | %zu | %zu |\n", f.name, median(ta), median(to), median(to) / median(ta), static_cast<std::size_t>(fs::file_size(pa)),
                static_cast<std::size_t>(fs::file_size(po)));
  }

  std::printf("\nDamaged files (7 truncations + 64 overwritten bytes each): read / error / crash / hang\n\n");
  std::printf("| format | OIIO | ao |\n|---|---|---|\n");
  std::mt19937 rng(7);
  for (const Format& f : kFormats) {
    if (f.bits == 16) continue;  // same readers as the 8-bit rows
    const std::string good = read_all(dir / (std::string("ao") + f.ext));
    const bool ao_reads = std::string(f.ext) == ".png" || std::string(f.ext) == ".exr";
    int oiio[4] = {}, aor[4] = {};
    std::vector<std::string> damaged;
    for (int k = 1; k < 8; ++k) damaged.push_back(good.substr(0, good.size() * k / 8));
    for (int k = 0; k < 64; ++k) {
      std::string d = good;
      // Headers and the first chunks hold the sizes and layouts a reader trusts: damage there is
      // the interesting case, so half the offsets fall in the first 256 bytes.
      const std::size_t at = k % 2 ? rng() % std::min<std::size_t>(256, d.size()) : rng() % d.size();
      d[at] = static_cast<char>(rng() & 0xff);
      damaged.push_back(d);
    }
    for (const std::string& d : damaged) {
      const fs::path p = dir / (std::string("damaged") + f.ext);
      std::ofstream(p, std::ios::binary).write(d.data(), static_cast<std::streamsize>(d.size()));
      for (const char* reader : {"oiio", "ao"}) {
        if (std::string(reader) == "ao" && !ao_reads) continue;
        const Outcome o = in_child("/proc/self/exe", reader, p);
        ++(std::string(reader) == "ao" ? aor : oiio)[static_cast<int>(o)];
        if (o == Outcome::Crash || o == Outcome::Hang) {  // kept for a look: the file and how it was damaged
          const fs::path keep = fs::temp_directory_path() / ("ao-image-formats-" + std::string(o == Outcome::Crash ? "crash-" : "hang-") + reader + "-" +
                                                             std::to_string(&d - damaged.data()) + f.ext);
          fs::copy_file(p, keep, fs::copy_options::overwrite_existing);
          std::printf("(kept %s)\n", keep.c_str());
        }
      }
    }
    std::printf("| %s | %d / %d / %d / %d | ", f.name, oiio[0], oiio[1], oiio[2], oiio[3]);
    if (ao_reads) std::printf("%d / %d / %d / %d |\n", aor[0], aor[1], aor[2], aor[3]);
    else std::printf("(not read) |\n");
  }
  fs::remove_all(dir);
  return 0;
}
