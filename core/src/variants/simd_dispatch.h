// SPDX-License-Identifier: MIT
// Picks, once per process, the widest of the SIMD targets Highway compiled a kernel for that
// this CPU runs: what HWY_DYNAMIC_DISPATCH does, without libhwy.so. Loading libhwy.so (1.0.3,
// Debian 12) runs a timer calibration in a static initialiser: 5.9 ms of every process that
// loads libssao (benchmarks/cold_start.c, docs/architecture.md "Cold start"), for a dispatch that
// needs only cpuid. The kernels themselves still come from Highway's headers.
//
// Use inside namespace ssao, after the per-target part of a foreach_target file:
//   static const auto row = SSAO_BEST_TARGET(hemisphere_row);
#pragma once

#include <hwy/highway.h>

namespace ssao {

enum class SimdTarget { avx3, avx2, sse4, ssse3, baseline };

// The widest target this CPU and its operating system support (cpuid and xgetbv; Highway's
// own requirements per target), computed once.
SimdTarget cpu_simd_target();

// The first of the candidates (widest first; nullptr: not compiled) that the CPU runs.
template <class Function>
Function choose_target(Function avx3, Function avx2, Function sse4, Function ssse3,
                       Function baseline) {
  const SimdTarget cpu = cpu_simd_target();
  const Function widest_first[] = {avx3, avx2, sse4, ssse3};
  for (int t = int(cpu); t < int(SimdTarget::baseline); ++t) {
    if (widest_first[t] != nullptr) return widest_first[t];
  }
  return baseline;
}

}  // namespace ssao

#if HWY_TARGETS & HWY_AVX3
#define SSAO_TARGET_AVX3(fn) &N_AVX3::fn
#else
#define SSAO_TARGET_AVX3(fn) nullptr
#endif
#if HWY_TARGETS & HWY_AVX2
#define SSAO_TARGET_AVX2(fn) &N_AVX2::fn
#else
#define SSAO_TARGET_AVX2(fn) nullptr
#endif
#if HWY_TARGETS & HWY_SSE4
#define SSAO_TARGET_SSE4(fn) &N_SSE4::fn
#else
#define SSAO_TARGET_SSE4(fn) nullptr
#endif
#if HWY_TARGETS & HWY_SSSE3
#define SSAO_TARGET_SSSE3(fn) &N_SSSE3::fn
#else
#define SSAO_TARGET_SSSE3(fn) nullptr
#endif

#define SSAO_BEST_TARGET(fn)                                                                   \
  ::ssao::choose_target<decltype(&HWY_STATIC_DISPATCH(fn))>(                                   \
      SSAO_TARGET_AVX3(fn), SSAO_TARGET_AVX2(fn), SSAO_TARGET_SSE4(fn), SSAO_TARGET_SSSE3(fn), \
      &HWY_STATIC_DISPATCH(fn))
