// Non-temporal ("streaming") stores for large outputs. An ordinary store to a line not in the
// caches first reads the line from memory (read for ownership), so writing an output column
// moves its bytes twice; a streaming store writes whole lines through write-combining buffers
// and skips that read, but leaves the line out of the caches. So the kernel streams only the
// outputs of calls too large for their lines to stay cached anyway (stream_min_bytes), and only
// the whole lines inside a full block's range: anything else is an ordinary copy.
//
// tools/memory_floor.cpp compares the two on a default call's traffic ("out": ordinary stores,
// "stream": streaming ones); where the outputs overflow the caches, streaming moves each output
// byte once instead of twice, and the call's memory floor rises by about half.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>

#if defined(__SSE2__)
#include <immintrin.h>
#endif

namespace epc_fast {

// A call streams its outputs when they total at least this many bytes (16 MiB: several times
// a core's L2 here, about a desktop's whole L3), i.e. from about 3.4e5 points of a default call.
constexpr std::size_t stream_min_bytes = std::size_t{16} << 20;

// Whether this build has streaming stores (x86-64 from SSE2 on, which is every x86-64 CPU).
constexpr bool streaming_stores =
#if defined(__SSE2__)
    true;
#else
    false;
#endif

// Copies `bytes` from `from` to `to`: the whole cache lines of `to`'s range with streaming
// stores, the partial lines at its ends (if any) with ordinary ones, so that a line shared with
// a neighbouring range (another block, maybe another thread's) is never streamed. `from` needs
// no alignment. The streamed lines are ordered before later stores only by stream_fence().
inline void stream_copy(void* to, const void* from, std::size_t bytes) noexcept {
    auto* d = static_cast<unsigned char*>(to);
    const auto* s = static_cast<const unsigned char*>(from);
#if defined(__SSE2__)
    const std::size_t head = (64 - (reinterpret_cast<std::uintptr_t>(d) & 63)) & 63;
    if (head < bytes) {
        const std::size_t end = head + (bytes - head) / 64 * 64;  // after the last whole line
        std::memcpy(d, s, head);
        for (std::size_t i = head; i < end; i += 64) {
#if defined(__AVX512F__)
            _mm512_stream_si512(reinterpret_cast<__m512i*>(d + i), _mm512_loadu_si512(s + i));
#elif defined(__AVX__)
            for (std::size_t k = i; k < i + 64; k += 32)
                _mm256_stream_si256(reinterpret_cast<__m256i*>(d + k),
                                    _mm256_loadu_si256(reinterpret_cast<const __m256i*>(s + k)));
#else
            for (std::size_t k = i; k < i + 64; k += 16)
                _mm_stream_si128(reinterpret_cast<__m128i*>(d + k),
                                 _mm_loadu_si128(reinterpret_cast<const __m128i*>(s + k)));
#endif
        }
        std::memcpy(d + end, s + end, bytes - end);
        return;
    }
#endif
    std::memcpy(d, s, bytes);
}

// Makes this thread's streaming stores visible, in order, before its later stores: each thread
// that streamed calls it before its results are read (or overwritten by ordinary stores).
inline void stream_fence() noexcept {
#if defined(__SSE2__)
    _mm_sfence();
#endif
}

}  // namespace epc_fast
