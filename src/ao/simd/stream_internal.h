// SPDX-License-Identifier: Apache-2.0
// Streaming (non-temporal) copies, for data written once and read later by another pass (the
// G-buffer's channels): the stores skip reading every destination cache line into the cache before
// overwriting it, half the memory traffic of plain stores. 16-byte SSE2 stores, which every x86-64
// CPU has (no dispatch needed); the instructions stay in the kernel layer.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>

#include <emmintrin.h>

namespace ao::simd {

/// Copies `bytes` bytes from src to dst with streaming stores where dst is 16-byte aligned, plain
/// stores at the unaligned ends. Call stream_fence() before other threads may read what was written.
inline void stream_copy(void* dst, const void* src, std::size_t bytes) {
  auto* d = static_cast<unsigned char*>(dst);
  const auto* s = static_cast<const unsigned char*>(src);
  const std::size_t head = std::min(bytes, (16 - reinterpret_cast<std::uintptr_t>(d) % 16) % 16);
  std::memcpy(d, s, head);
  d += head, s += head, bytes -= head;
  for (; bytes >= 16; d += 16, s += 16, bytes -= 16)
    _mm_stream_si128(reinterpret_cast<__m128i*>(d), _mm_loadu_si128(reinterpret_cast<const __m128i*>(s)));
  std::memcpy(d, s, bytes);
}

/// Orders the streaming stores before any later store: what they wrote is visible to the thread
/// that next reads it.
inline void stream_fence() { _mm_sfence(); }

}  // namespace ao::simd
