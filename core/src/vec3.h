// SPDX-License-Identifier: MIT
// The project's one 3-vector: the library's view-space geometry in floats (Vec3), and, header
// only and depending on nothing, the doubles of the tests' analytic scenes and of POV-Ray's
// scene reader (povray_bridge/scene), which include it too.
#pragma once

#include <cmath>

namespace ssao {

template <typename T>
struct Vector3 {
  T x = T(0), y = T(0), z = T(0);
};
using Vec3 = Vector3<float>;

// The scalar of a product takes the vector's type (a double constant times a Vec3 stays float),
// so it is not deduced from the argument.
template <typename T>
struct ScalarOf {
  using type = T;
};

template <typename T>
inline Vector3<T> operator+(Vector3<T> a, Vector3<T> b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
template <typename T>
inline Vector3<T> operator-(Vector3<T> a, Vector3<T> b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
template <typename T>
inline Vector3<T> operator-(Vector3<T> a) {
  return {-a.x, -a.y, -a.z};
}
template <typename T>
inline Vector3<T> operator*(Vector3<T> a, typename ScalarOf<T>::type s) {
  return {a.x * s, a.y * s, a.z * s};
}
template <typename T>
inline Vector3<T> operator*(typename ScalarOf<T>::type s, Vector3<T> a) {
  return a * s;
}
template <typename T>
inline T dot(Vector3<T> a, Vector3<T> b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
template <typename T>
inline Vector3<T> cross(Vector3<T> a, Vector3<T> b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
template <typename T>
inline T length(Vector3<T> a) {
  return std::sqrt(dot(a, a));
}
// a / |a|, or a itself when |a| = 0.
template <typename T>
inline Vector3<T> normalized(Vector3<T> a) {
  const T len = length(a);
  return len > T(0) ? a * (T(1) / len) : a;
}

// Returns a / |a|, or `fallback` when a is zero, tiny or not finite.
inline Vec3 normalize_or(Vec3 a, Vec3 fallback) {
  const float len = length(a);
  if (!(len > 1e-20f) || !std::isfinite(len)) return fallback;
  return a * (1.0f / len);
}

// Builds an orthonormal basis (t, b) around unit n without branches on a special axis
// (Duff et al. 2017, "Building an Orthonormal Basis, Revisited").
inline void orthonormal_basis(Vec3 n, Vec3& t, Vec3& b) {
  const float sign = std::copysign(1.0f, n.z);
  const float a = -1.0f / (sign + n.z);
  const float c = n.x * n.y * a;
  t = {1.0f + sign * n.x * n.x * a, sign * c, -sign * n.x};
  b = {c, sign + n.y * n.y * a, -n.y};
}

// n or -n, whichever has a non-negative component along `towards` (a face's normal turned to
// the camera, a plane's to a surface's side).
inline Vec3 turned_towards(Vec3 n, Vec3 towards) { return dot(n, towards) < 0.0f ? n * -1.0f : n; }

inline float saturate(float v) { return v < 0.0f ? 0.0f : (v > 1.0f ? 1.0f : v); }

}  // namespace ssao
