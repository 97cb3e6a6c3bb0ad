// SPDX-License-Identifier: MIT
// SSAO_VECTORIZE: compiles a plain loop once per x86 vector width (AVX-512, AVX2, baseline)
// and picks the widest the CPU has when the library loads (GCC function multiversioning). For
// the simple streaming loops; the kernels with gathers use Google Highway instead.
#pragma once

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && \
    !defined(__SANITIZE_ADDRESS__)
#define SSAO_VECTORIZE __attribute__((target_clones("avx512f", "avx2", "default")))
#else
#define SSAO_VECTORIZE
#endif
