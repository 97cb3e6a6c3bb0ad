// SPDX-License-Identifier: MIT
#include "variants/simd_dispatch.h"

#if defined(__x86_64__) || defined(__i386__)
#include <cpuid.h>
#endif

#include <cstdint>
#include <cstdlib>
#include <cstring>

namespace ssao {
namespace {

#if defined(__x86_64__) || defined(__i386__)
bool bit(uint32_t word, int b) { return (word >> b) & 1u; }

// The requirements of Highway 1.0.3's x86 targets (hwy/targets.cc), checked the same way.
SimdTarget detect() {
  uint32_t a, b, c1, d;
  if (!__get_cpuid(1, &a, &b, &c1, &d)) return SimdTarget::baseline;
  uint32_t b7 = 0, c7, d7;
  if (!__get_cpuid_count(7, 0, &a, &b7, &c7, &d7)) b7 = 0;
  uint32_t c81 = 0, b81, d81;
  if (!__get_cpuid(0x80000001u, &a, &b81, &c81, &d81)) c81 = 0;
  const bool ssse3 = bit(c1, 9);
  const bool sse4 = ssse3 && bit(c1, 19) && bit(c1, 20) && bit(c1, 1) && bit(c1, 25);
  // The OS must save the vector registers: xgetbv's SSE+AVX state (bits 1-2) and AVX-512's
  // opmask and upper halves (bits 5-7).
  uint64_t xcr0 = 0;
  if (bit(c1, 27)) {  // OSXSAVE
    uint32_t low, high;
    __asm__("xgetbv" : "=a"(low), "=d"(high) : "c"(0));
    xcr0 = (uint64_t(high) << 32) | low;
  }
  const bool avx_state = (xcr0 & 0x6) == 0x6, avx512_state = (xcr0 & 0xe0) == 0xe0;
  const bool avx2 = sse4 && avx_state && bit(c1, 28) && bit(b7, 5) && bit(b7, 3) && bit(b7, 8) &&
                    bit(c1, 29) && bit(c1, 12) && bit(c81, 5) && bit(c1, 22);
  const bool avx3 =
      avx2 && avx512_state && bit(b7, 16) && bit(b7, 17) && bit(b7, 30) && bit(b7, 31);
  return avx3    ? SimdTarget::avx3
         : avx2  ? SimdTarget::avx2
         : sse4  ? SimdTarget::sse4
         : ssse3 ? SimdTarget::ssse3
                 : SimdTarget::baseline;
}
#else
SimdTarget detect() { return SimdTarget::baseline; }
#endif

}  // namespace

// $SSAO_SIMD_TARGET (avx3, avx2, sse4, ssse3 or baseline) narrows the choice: the kernels of
// a wider target sum their lanes in another order, so the last bits of the AO follow the CPU.
// Machines that must agree bit for bit (a farm of mixed CPUs; the Linux and the Windows build
// compared in tests/windows) name the same target. A target the CPU lacks, or an unknown name,
// is ignored.
static SimdTarget narrowed(SimdTarget cpu) {
  const char* wanted = std::getenv("SSAO_SIMD_TARGET");
  if (wanted == nullptr) return cpu;
  const char* names[] = {"avx3", "avx2", "sse4", "ssse3", "baseline"};
  for (int t = 0; t <= int(SimdTarget::baseline); ++t) {
    if (std::strcmp(wanted, names[t]) == 0) return t >= int(cpu) ? SimdTarget(t) : cpu;
  }
  return cpu;
}

SimdTarget cpu_simd_target() {
  static const SimdTarget target = narrowed(detect());
  return target;
}

}  // namespace ssao
