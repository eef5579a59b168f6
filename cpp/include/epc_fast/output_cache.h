// Memory for output columns that outlives their arrays: a block freed by one call's result is
// kept (up to a limit) and handed to a later call that asks for about as many bytes.
//
// Why: a new array's pages are mapped on first write, and the operating system zeroes each one
// first: a page fault per page and one more pass over the outputs' memory, which every call of
// a scan or a benchmark loop pays again, the results of the call before having just been
// dropped. A kept block's pages stay mapped: the next call only writes them. The kept memory is
// bounded by limit() (0 keeps nothing), and a block is only reused for a request within a
// quarter of its size, so a small call never pins a large block.
#pragma once

#include <cstddef>
#include <cstdlib>
#include <mutex>
#include <new>
#include <vector>

#if defined(__linux__)
#include <sys/mman.h>
#elif defined(_WIN32)
#include <malloc.h>
#endif

namespace epc_fast {

class OutputCache {
public:
    // A block of `capacity` bytes; `fresh` when just allocated (its pages never touched).
    struct Block {
        void* data = nullptr;
        std::size_t capacity = 0;
        bool fresh = false;
    };

    OutputCache() { kept_.reserve(max_kept); }
    OutputCache(const OutputCache&) = delete;
    OutputCache& operator=(const OutputCache&) = delete;
    ~OutputCache() { set_limit(0); }

    // Requests smaller than this are not worth keeping: their pages cost little to fault in.
    static constexpr std::size_t min_bytes = std::size_t{1} << 20;

    // A block of at least `bytes` (> 0): a kept one of at most bytes + bytes / 4, the smallest
    // such, else a new one (std::bad_alloc when there is no memory for it).
    Block acquire(std::size_t bytes) {
        {
            std::lock_guard<std::mutex> lock(mutex_);
            auto best = kept_.end();
            for (auto it = kept_.begin(); it != kept_.end(); ++it)
                if (it->capacity >= bytes && it->capacity - bytes <= bytes / 4 &&
                    (best == kept_.end() || it->capacity < best->capacity))
                    best = it;
            if (best != kept_.end()) {
                Block block = *best;
                kept_.erase(best);
                retained_ -= block.capacity;
                block.fresh = false;
                return block;
            }
        }
        return allocate(bytes);
    }

    // Gives back a block from acquire: kept when it fits under the limit (the oldest kept blocks
    // freed to make room), else freed.
    void release(void* data, std::size_t capacity) noexcept {
        std::lock_guard<std::mutex> lock(mutex_);
        if (capacity <= limit_) {
            shrink_to(limit_ - capacity, max_kept - 1);
            kept_.push_back(Block{data, capacity, false});
            retained_ += capacity;
        } else {
            free_block(data);
        }
    }

    // Sets the most bytes kept (0: none), freeing the oldest blocks beyond it.
    void set_limit(std::size_t bytes) noexcept {
        std::lock_guard<std::mutex> lock(mutex_);
        limit_ = bytes;
        shrink_to(limit_, max_kept);
    }

    std::size_t limit() const {
        std::lock_guard<std::mutex> lock(mutex_);
        return limit_;
    }

    // Bytes kept now, waiting for a call.
    std::size_t retained() const {
        std::lock_guard<std::mutex> lock(mutex_);
        return retained_;
    }

private:
    // A new block: 64-byte aligned (a cache line, an AVX-512 vector), or for 4 MiB and more
    // aligned to 2 MiB and marked for transparent huge pages, as NumPy marks its own arrays.
    static Block allocate(std::size_t bytes) {
        constexpr std::size_t huge = std::size_t{1} << 21;
        const bool large = bytes >= 2 * huge;
        const std::size_t align = large ? huge : 64;
        if (bytes > static_cast<std::size_t>(-1) - align) throw std::bad_alloc();
        const std::size_t capacity = (bytes + align - 1) / align * align;
#if defined(_WIN32)
        void* data = _aligned_malloc(capacity, align);
#else
        void* data = std::aligned_alloc(align, capacity);
#endif
        if (data == nullptr) throw std::bad_alloc();
#if defined(__linux__) && defined(MADV_HUGEPAGE)
        if (large) madvise(data, capacity, MADV_HUGEPAGE);  // advice only: failure is harmless
#endif
        return Block{data, capacity, true};
    }

    static void free_block(void* data) noexcept {
#if defined(_WIN32)
        _aligned_free(data);
#else
        std::free(data);
#endif
    }

    // Frees the oldest kept blocks until at most `bytes` in at most `count` blocks are kept
    // (the mutex held).
    void shrink_to(std::size_t bytes, std::size_t count) noexcept {
        std::size_t drop = 0;
        while (retained_ > bytes || kept_.size() - drop > count) {
            free_block(kept_[drop].data);
            retained_ -= kept_[drop].capacity;
            ++drop;
        }
        kept_.erase(kept_.begin(), kept_.begin() + static_cast<std::ptrdiff_t>(drop));
    }

    // At most this many blocks are kept: the list never allocates after construction, so
    // release, called from an array's destructor, cannot fail.
    static constexpr std::size_t max_kept = 64;

    mutable std::mutex mutex_;
    std::vector<Block> kept_;  // oldest first

    std::size_t limit_ = 0;
    std::size_t retained_ = 0;
};

}  // namespace epc_fast
