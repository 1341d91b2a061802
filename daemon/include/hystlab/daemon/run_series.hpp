#pragma once
// A run's record of (displacement, force), kept for the fits: appended on the acquisition thread
// in chunks of fixed size, and shared with other threads by pointer.
//
// Why chunks: the record was two vectors, and each descent copied up to 65,536 of its samples on
// the acquisition thread to score the partial table (and every growth of the vectors copied the
// whole record there). A chunk is never written once anyone else holds it (an append to a shared
// chunk writes a private copy of that one chunk first), so share() is O(chunks), a copy of a
// series is O(chunks), and a reader on another thread needs no lock.
//
// Bounded: 16 bytes a sample. At kMaxSamples (2^21, 32 MB) every other sample is dropped and from
// then on every second one offered is kept (stride 2, then 4, ...): a day at 1 kHz (8.6e7
// samples) keeps 1.3e6, every 64th. The halving moves 2^20 values in place once per doubling of the run
// (about 2 ms, a late wake-up that block reads lose nothing to); `halvings` counts them, so that
// indices into the record can follow.
#include <array>
#include <atomic>
#include <cstddef>
#include <memory>
#include <vector>

namespace hystlab::daemon {

// Two columns, contiguous: what the fits and the scores take.
struct Columns {
  std::vector<double> x, f;
};

class RunSeries {
 public:
  static constexpr std::size_t kMaxSamples = std::size_t{1} << 21;  // then thinned 2:1, and every second sample after kept
  static constexpr std::size_t kChunk = 4096;                       // 64 KiB a chunk: below malloc's mmap threshold
  struct Chunk {
    std::array<double, kChunk> x, f;
    // Shared records holding it. Released (release) by the reader when done and read (acquire)
    // before a write in place: that orders the reader's reads before the writes, which a
    // use_count() (a relaxed load) does not.
    mutable std::atomic<int> readers{0};
  };

  // The first `size` samples of a series, as they were when shared: readable on any thread.
  struct Shared {
    struct Hold {  // the chunks, counted as read until the last copy of this Shared is gone
      std::vector<std::shared_ptr<const Chunk>> chunks;
      Hold() = default;
      Hold(const Hold&) = delete;
      Hold& operator=(const Hold&) = delete;
      ~Hold();
    };
    std::shared_ptr<const Hold> hold;
    std::size_t size = 0;
    [[nodiscard]] double x(std::size_t i) const noexcept { return hold->chunks[i / kChunk]->x[i % kChunk]; }
    [[nodiscard]] double f(std::size_t i) const noexcept { return hold->chunks[i / kChunk]->f[i % kChunk]; }
    // At most n samples, evenly spread (a score of bounded cost whatever the record's length).
    [[nodiscard]] Columns thinned(std::size_t n) const;
  };

  RunSeries() = default;
  // A copy shares the chunks (each written only as its own copy from then on), never the spares.
  RunSeries(const RunSeries& o) : chunks_(o.chunks_), size_(o.size_), stride_(o.stride_), halvings_(o.halvings_), offered_(o.offered_) {}
  RunSeries& operator=(const RunSeries& o) {
    if (this != &o) *this = RunSeries(o);
    return *this;
  }
  RunSeries(RunSeries&& o) noexcept { *this = std::move(o); }
  RunSeries& operator=(RunSeries&& o) noexcept;  // leaves o empty
  ~RunSeries() = default;

  void add(double xi, double fi);
  [[nodiscard]] std::size_t size() const noexcept { return size_; }
  [[nodiscard]] bool empty() const noexcept { return size_ == 0; }
  [[nodiscard]] double x(std::size_t i) const noexcept { return chunks_[i / kChunk]->x[i % kChunk]; }
  [[nodiscard]] double f(std::size_t i) const noexcept { return chunks_[i / kChunk]->f[i % kChunk]; }
  // Samples [b, e) into out (its capacity reused: no allocation once it is large enough).
  void copy(std::size_t b, std::size_t e, Columns& out) const;
  [[nodiscard]] Shared share() const;
  // Every sample, contiguous (the finisher's: O(N), off the acquisition thread).
  [[nodiscard]] Columns columns() const;
  // 1, then 2, 4, ... once thinned: the record keeps every stride-th sample offered.
  [[nodiscard]] std::size_t stride() const noexcept { return stride_; }
  [[nodiscard]] std::size_t halvings() const noexcept { return halvings_; }

 private:
  void halve();
  std::shared_ptr<Chunk> fresh();                              // a spare chunk, else a new one
  static bool mine(const std::shared_ptr<Chunk>& c) noexcept;  // held by no one else: writable in place
  void own(std::size_t k);                                     // chunk k made writable
  std::vector<std::shared_ptr<Chunk>> chunks_, spare_;
  std::size_t size_ = 0, stride_ = 1, halvings_ = 0, offered_ = 0;
};

}  // namespace hystlab::daemon
