// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The one rule by which every per-sample loop over a motion shares its samples between threads
// and warm-starts them (docs/developers/determinism.md): the samples are cut into fixed chunks
// of kSampleChunk consecutive samples; a chunk goes to one thread, which evaluates its samples
// in order, so a sample may be warm-started from its predecessor in the chunk. The chunks, not
// the thread count, decide every warm start, and every result is the same, to the bit, for any
// thread count. The motion problem's loop (outer_nlp/motion_problem.cpp), the multi-contact
// evaluators (inner_qp/multi_contact_dynamics.hpp, sensitivity/multi_contact_gradient.hpp) all
// run it. (Loops whose samples do not depend on one another need no such rule.)

#include <algorithm>

namespace mcopt {

inline constexpr int kSampleChunk = 8;

/// How many chunks `sampleCount` samples make.
inline int sampleChunkCount(int sampleCount) { return (sampleCount + kSampleChunk - 1) / kSampleChunk; }

/// Calls f(s, predecessor) for every sample s in [0, sampleCount), where predecessor is s − 1
/// when s − 1 is in the same chunk (and was evaluated just before s by the same thread) and −1
/// at a chunk's first sample. Inside an OpenMP parallel region the chunks are shared between
/// its threads (a work-sharing loop every thread of the region must reach); outside one, one
/// thread runs them all in order.
template <class Function>
void forEachSampleInChunks(int sampleCount, Function&& f) {
  const int chunks = sampleChunkCount(sampleCount);
#pragma omp for schedule(static)
  for (int chunk = 0; chunk < chunks; ++chunk) {
    const int first = chunk * kSampleChunk, last = std::min(sampleCount, first + kSampleChunk);
    for (int s = first; s < last; ++s) f(s, s > first ? s - 1 : -1);
  }
}

}  // namespace mcopt
