// SPDX-License-Identifier: MIT
// Sine, cosine, atan2 and pow whose float results are the same bits with every C library:
// computed in double and rounded to float. glibc's and MinGW-w64's sinf, cosf, atan2f and powf
// differ in the last bit for some arguments (the Windows DLL's AO differed from the Linux
// library's in up to 2 % of the pixels, tests/windows/compare_ao.py); two double results within
// an ulp of each other round to the same float except within 2^-29 of a rounding boundary.
#pragma once

#include <cmath>

namespace ssao {

inline float portable_sin(float x) { return float(std::sin(double(x))); }
inline float portable_cos(float x) { return float(std::cos(double(x))); }
inline float portable_atan2(float y, float x) { return float(std::atan2(double(y), double(x))); }
inline float portable_pow(float x, float y) { return float(std::pow(double(x), double(y))); }

}  // namespace ssao
