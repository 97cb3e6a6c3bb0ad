// SPDX-License-Identifier: MIT
// SSAO_VECTORIZE: compiles a plain loop once per x86 vector width (AVX-512, AVX2, baseline)
// and picks the widest the CPU has when the library loads (GCC function multiversioning). For
// the simple streaming loops; the kernels with gathers use Google Highway instead.
#pragma once

// Not in sanitizer builds: the clones' ifunc resolvers run while the dynamic loader relocates
// the library, before the sanitizer's runtime is initialised, and crash there when instrumented
// (ThreadSanitizer: a segfault before main). Not on Windows, which has no ifunc: there these
// loops are compiled for the baseline only. Every clone gives the same bits: the files that use
// it are compiled with -ffp-contract=off (core/CMakeLists.txt).
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(_WIN32) && \
    !defined(__SANITIZE_ADDRESS__) && !defined(__SANITIZE_THREAD__)
#define SSAO_VECTORIZE __attribute__((target_clones("avx512f", "avx2", "default")))
#else
#define SSAO_VECTORIZE
#endif
