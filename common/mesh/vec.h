// Small fixed-size vectors: just enough arithmetic for geometry code.
// Plain aggregates so arrays of them are arrays of floats (no padding).
#pragma once

#include <cmath>
#include <cstdint>

namespace meshstream {

template <class T>
struct Vec2 {
  T x{}, y{};
};

template <class T>
struct Vec3 {
  T x{}, y{}, z{};

  constexpr T& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }
  constexpr const T& operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
  friend constexpr bool operator==(const Vec3&, const Vec3&) = default;
};

template <class T>
struct Vec4 {
  T x{}, y{}, z{}, w{};
  friend constexpr bool operator==(const Vec4&, const Vec4&) = default;
};

using Vec2f = Vec2<float>;
using Vec3f = Vec3<float>;
using Vec4f = Vec4<float>;
using Vec3d = Vec3<double>;
// Integer grid points (the codec's quantized positions) and their exact
// products (cross products of grid differences need 64 bits).
using Vec3i = Vec3<int32_t>;
using Vec3l = Vec3<int64_t>;

template <class T>
constexpr Vec3<T> operator+(Vec3<T> a, Vec3<T> b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
template <class T>
constexpr Vec3<T> operator-(Vec3<T> a, Vec3<T> b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
template <class T>
constexpr Vec3<T> operator-(Vec3<T> a) {
  return {-a.x, -a.y, -a.z};
}
template <class T>
constexpr Vec3<T> operator*(Vec3<T> a, T s) {
  return {a.x * s, a.y * s, a.z * s};
}
template <class T>
constexpr Vec3<T> operator*(T s, Vec3<T> a) {
  return {a.x * s, a.y * s, a.z * s};
}
template <class T>
constexpr Vec3<T> operator/(Vec3<T> a, T s) {
  return {a.x / s, a.y / s, a.z / s};
}
template <class T>
constexpr Vec3<T>& operator+=(Vec3<T>& a, Vec3<T> b) {
  a = a + b;
  return a;
}
template <class T>
constexpr Vec3<T>& operator-=(Vec3<T>& a, Vec3<T> b) {
  a = a - b;
  return a;
}
template <class T>
constexpr Vec3<T>& operator*=(Vec3<T>& a, T s) {
  a = a * s;
  return a;
}

template <class T>
constexpr T dot(Vec3<T> a, Vec3<T> b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
template <class T>
constexpr Vec3<T> cross(Vec3<T> a, Vec3<T> b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
template <class T>
inline T length(Vec3<T> a) {
  return std::sqrt(dot(a, a));
}
template <class T>
constexpr T squared_length(Vec3<T> a) {
  return dot(a, a);
}
// Returns the zero vector for a zero input instead of NaNs.
template <class T>
inline Vec3<T> normalized(Vec3<T> a) {
  T len = length(a);
  return len > T(0) ? a / len : Vec3<T>{};
}

// The same vector in another component type (static_cast per component:
// exact for grid points to double, widening to int64).
template <class U, class T>
constexpr Vec3<U> vec3_cast(Vec3<T> v) {
  return {static_cast<U>(v.x), static_cast<U>(v.y), static_cast<U>(v.z)};
}

inline Vec3d to_double(Vec3f v) { return {v.x, v.y, v.z}; }
inline Vec3d to_double(Vec3i v) { return vec3_cast<double>(v); }
inline Vec3f to_float(Vec3d v) {
  return {static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z)};
}

}  // namespace meshstream
