// SPDX-License-Identifier: MIT
// Scratch buffers of one tile or row band (filter planes, rows being filtered, upsampled
// values): from oneTBB's scalable allocator, whose per-thread pools keep freed blocks for the
// next tile and the next run. With the C library's malloc, a run's freed scratch went back to
// the system (heap trims and madvise, each a TLB shootdown across the pool's threads) and came
// back as page faults in the next run: about 1,100 page faults and several ms of system time per
// 640x360 run (getrusage, docs/architecture.md "Cold start").
#pragma once

#if SSAO_THREADS_TBB
#include <tbb/scalable_allocator.h>
#endif

#include <memory>
#include <vector>

namespace ssao {

// Sanitizer builds keep the C library's allocator, which they instrument: an overrun of a
// scratch buffer must stay visible to AddressSanitizer.
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define SSAO_SCRATCH_ALLOCATOR(T) std::allocator<T>
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define SSAO_SCRATCH_ALLOCATOR(T) std::allocator<T>
#endif
#endif
#if !defined(SSAO_SCRATCH_ALLOCATOR) && SSAO_THREADS_TBB
#define SSAO_SCRATCH_ALLOCATOR(T) tbb::scalable_allocator<T>
#endif
#ifndef SSAO_SCRATCH_ALLOCATOR  // the std::thread build (tiles.cpp): no oneTBB
#define SSAO_SCRATCH_ALLOCATOR(T) std::allocator<T>
#endif

template <class T>
using ScratchVector = std::vector<T, SSAO_SCRATCH_ALLOCATOR(T)>;

}  // namespace ssao
