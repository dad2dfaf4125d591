// SPDX-License-Identifier: Apache-2.0
// ao: ambient occlusion on the CPU. The only place errors become exit codes:
//   0 success, 1 bad input (file, option value, including a value of the wrong type), 2 bad usage
//   (unknown option, missing argument), 3 system failure (disk, library, not enough memory),
//   4 internal error.
#include <malloc.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <functional>
#include <limits>
#include <memory>
#include <new>

#include <CLI/CLI.hpp>
#include <tbb/global_control.h>

#include "ao/core/error.h"
#include "ao/io/atomic_file.h"
#include "app.h"
#include "field_names.h"
#include "parse_errors.h"

namespace {

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define AO_UNDER_SANITIZER 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer) || __has_feature(memory_sanitizer)
#define AO_UNDER_SANITIZER 1
#endif
#endif

/// Keep freed memory in the process, and give the main heap's next 256 MiB transparent huge pages.
/// Blocks up to 32 MB (glibc's largest mmap threshold) come from the heap, and the heap is never
/// trimmed: otherwise glibc returns large blocks (a bake's coverage fragments, a map's scratch
/// images, each frame's images in `ao view`) to the kernel when they are freed, and the next one
/// faults in fresh zeroed pages (a 1024^2 bake at 8 rays spent 14% of its CPU in the kernel's page
/// faults; keeping them cut its CPU by 5%). Then the heap is grown once by 256 MiB (address space:
/// pages come as they are touched) and that stretch advised to the kernel as huge pages
/// (MADV_HUGEPAGE; Debian's kernels give them to advised memory only): a 2 MiB page takes one
/// fault where 512 did, and the TLB covers 512 times as much of the mesh, the UV bins and the
/// filter's guides. A 1024^2 bake at 6 rays: page faults 7,700 -> 2,100, CPU about 0.95x, for 15 MB more
/// peak memory (docs/methods/bake.md, "Speed"). The process keeps the most memory it used at once
/// until it exits, which a command does soon; the library leaves malloc as its host set it.
void tune_malloc() {
  mallopt(M_MMAP_THRESHOLD, 32 << 20);
  mallopt(M_TRIM_THRESHOLD, std::numeric_limits<int>::max());
#if defined(__GLIBC__) && defined(MADV_HUGEPAGE) && !defined(AO_UNDER_SANITIZER)
  constexpr std::uintptr_t kStretch = std::uintptr_t{256} << 20, kBlock = std::uintptr_t{1} << 20;
  constexpr std::uintptr_t kHugePage = std::uintptr_t{2} << 20, kPage = 4096;
  // A block larger than what is free at the heap's top, under the mmap threshold: the heap grows
  // by it and the top pad. The pad then goes back to glibc's default (128 KiB), so that later
  // growth under an address-space limit asks for no more than it needs.
  mallopt(M_TOP_PAD, static_cast<int>(kStretch));
  void* block = std::malloc(kBlock);
  mallopt(M_TOP_PAD, 128 << 10);
  if (block == nullptr) return;
  // From the first 2 MiB boundary in the block to the heap's end (below it is what the program's
  // start allocated), if the block is where the heap just grew (not mapped elsewhere because the
  // heap could not grow).
  const auto at = reinterpret_cast<std::uintptr_t>(block);
  const std::uintptr_t from = (at + kHugePage - 1) & ~(kHugePage - 1);
  const std::uintptr_t to = reinterpret_cast<std::uintptr_t>(sbrk(0)) & ~(kPage - 1);
  if (to > from && to >= at + kBlock && to - (at + kBlock) <= kStretch + kHugePage)
    madvise(reinterpret_cast<void*>(from), to - from, MADV_HUGEPAGE);  // advice: its result does not matter
  std::free(block);
#endif
}

}  // namespace

int main(int argc, char** argv) {
  tune_malloc();
  CLI::App app("ao: ambient occlusion on the CPU. Ray-traced ground truth and published AO methods.", "ao");
  ao::cli::GlobalOptions global;
  std::function<int()> action;
  ao::cli::add_ao_commands(app, global, action);

  // Interrupted runs remove their temporary files, and a file size limit is an error like a full
  // disk (atomic_file.h).
  ao::remove_temporaries_on_signals();
  ao::ignore_file_size_signal();
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // One line in ao's words; a value of the wrong type or out of range ("--width abc", "--seed -1")
    // is a bad value (1), like the values the subcommands check; anything else bad usage (2).
    return ao::cli::report_parse_error(app, e, argc, argv);
  }
  std::unique_ptr<tbb::global_control> limit;
  if (global.threads > 0)
    limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(global.threads));
  try {
    return action ? action() : 0;
  } catch (const ao::InputError& e) {
    // The job layer names request fields ("BakeRequest::padding"); the command line names its options.
    std::fprintf(stderr, "ao: error: %s\n", e.message(ao::cli::option_name).c_str());
    return 1;
  } catch (const ao::SystemError& e) {
    std::fprintf(stderr, "ao: error: %s\n", e.what());
    return 3;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "ao: error: out of memory\n");
    return 3;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ao: internal error: %s\n", e.what());
    return 4;
  }
}
