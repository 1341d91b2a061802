#include "hystlab/daemon/run_series.hpp"

#include <algorithm>

namespace hystlab::daemon {

RunSeries& RunSeries::operator=(RunSeries&& o) noexcept {
  chunks_ = std::move(o.chunks_), spare_ = std::move(o.spare_);
  size_ = o.size_, stride_ = o.stride_, halvings_ = o.halvings_, offered_ = o.offered_;
  o.chunks_.clear(), o.spare_.clear();
  o.size_ = 0, o.stride_ = 1, o.halvings_ = 0, o.offered_ = 0;
  return *this;
}

bool RunSeries::mine(const std::shared_ptr<Chunk>& c) noexcept { return c.use_count() == 1 && c->readers.load(std::memory_order_acquire) == 0; }

void RunSeries::own(std::size_t k) {
  if (mine(chunks_[k])) return;
  auto copy = fresh();
  copy->x = chunks_[k]->x;
  copy->f = chunks_[k]->f;
  chunks_[k] = std::move(copy);
}

RunSeries::Shared::Hold::~Hold() {
  for (const auto& c : chunks) c->readers.fetch_sub(1, std::memory_order_release);
}

void RunSeries::add(double xi, double fi) {
  if (stride_ > 1 && ++offered_ % stride_ != 0) return;
  if (size_ >= kMaxSamples) halve();
  const std::size_t k = size_ / kChunk, i = size_ % kChunk;
  if (k == chunks_.size()) {
    chunks_.push_back(fresh());  // every kChunk samples
  } else {
    own(k);  // shared (a copy, a reader): written only as our own copy
  }
  chunks_[k]->x[i] = xi;
  chunks_[k]->f[i] = fi;
  ++size_;
}

// Every second sample, in place (a chunk another holds is copied before it is written); O(N) once
// per doubling of the record (2^21 samples: 35 min at 1 kHz, then 70 min, ...). In place: the
// sample written at w is read from 2w >= w, so no sample is overwritten before it is read.
void RunSeries::halve() {
  std::size_t w = 0;
  for (std::size_t r = 0; r < size_; r += 2, ++w) {
    const std::size_t k = w / kChunk;
    if (w % kChunk == 0) own(k);
    chunks_[k]->x[w % kChunk] = x(r);
    chunks_[k]->f[w % kChunk] = f(r);
  }
  // The chunks freed are kept for the samples to come: the record's memory stays as it was (given
  // back, the heap was trimmed and re-faulted at every halving: 48 to 65 MB and back in bench_memory).
  for (std::size_t k = (w + kChunk - 1) / kChunk; k < chunks_.size(); ++k)
    if (mine(chunks_[k])) spare_.push_back(std::move(chunks_[k]));
  chunks_.resize((w + kChunk - 1) / kChunk);
  size_ = w;
  stride_ *= 2;
  ++halvings_;
  offered_ = 0;
}

std::shared_ptr<RunSeries::Chunk> RunSeries::fresh() {
  if (spare_.empty()) return std::make_shared<Chunk>();  // 64 KiB from the heap
  auto c = std::move(spare_.back());
  spare_.pop_back();
  return c;
}

void RunSeries::copy(std::size_t b, std::size_t e, Columns& out) const {
  out.x.clear(), out.f.clear();
  for (std::size_t i = b; i < e && i < size_; ++i) out.x.push_back(x(i)), out.f.push_back(f(i));
}

RunSeries::Shared RunSeries::share() const {
  auto hold = std::make_shared<Shared::Hold>();
  hold->chunks.assign(chunks_.begin(), chunks_.end());
  for (const auto& c : hold->chunks) c->readers.fetch_add(1, std::memory_order_relaxed);  // this thread's own later checks see it
  Shared s;
  s.hold = std::move(hold);
  s.size = size_;
  return s;
}

Columns RunSeries::columns() const {
  Columns c;
  copy(0, size_, c);
  return c;
}

Columns RunSeries::Shared::thinned(std::size_t n) const {
  Columns out;
  const std::size_t step = size > n ? (size + n - 1) / n : 1;
  out.x.reserve(size / step + 1), out.f.reserve(size / step + 1);
  for (std::size_t k = 0; k < size; k += step) out.x.push_back(x(k)), out.f.push_back(f(k));
  return out;
}

}  // namespace hystlab::daemon
