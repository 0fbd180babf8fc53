// Small vector / matrix types used everywhere in whitted.
//
// Vec3f is the shading and ray type (float); Vec3d and Mat4d carry scene transforms, which are
// composed in double precision (node hierarchies, large scales and offsets).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

namespace whitted {

template <typename T>
struct Vec2 {
    T x{}, y{};
    constexpr Vec2() = default;
    constexpr Vec2(T x_, T y_) : x(x_), y(y_) {}
    constexpr T operator[](int i) const { return i == 0 ? x : y; }
    constexpr Vec2 operator+(const Vec2& o) const { return {x + o.x, y + o.y}; }
    constexpr Vec2 operator-(const Vec2& o) const { return {x - o.x, y - o.y}; }
    constexpr Vec2 operator*(T s) const { return {x * s, y * s}; }
    constexpr bool operator==(const Vec2&) const = default;
};

template <typename T>
struct Vec3 {
    T x{}, y{}, z{};
    constexpr Vec3() = default;
    constexpr explicit Vec3(T s) : x(s), y(s), z(s) {}
    constexpr Vec3(T x_, T y_, T z_) : x(x_), y(y_), z(z_) {}
    template <typename U>
    constexpr explicit Vec3(const Vec3<U>& o) : x(T(o.x)), y(T(o.y)), z(T(o.z)) {}

    constexpr T operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
    constexpr T& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }
    constexpr Vec3 operator+(const Vec3& o) const { return {x + o.x, y + o.y, z + o.z}; }
    constexpr Vec3 operator-(const Vec3& o) const { return {x - o.x, y - o.y, z - o.z}; }
    constexpr Vec3 operator-() const { return {-x, -y, -z}; }
    constexpr Vec3 operator*(const Vec3& o) const { return {x * o.x, y * o.y, z * o.z}; }
    constexpr Vec3 operator/(const Vec3& o) const { return {x / o.x, y / o.y, z / o.z}; }
    constexpr Vec3 operator*(T s) const { return {x * s, y * s, z * s}; }
    constexpr Vec3 operator/(T s) const { return {x / s, y / s, z / s}; }
    constexpr Vec3& operator+=(const Vec3& o) { x += o.x; y += o.y; z += o.z; return *this; }
    constexpr Vec3& operator-=(const Vec3& o) { x -= o.x; y -= o.y; z -= o.z; return *this; }
    constexpr Vec3& operator*=(const Vec3& o) { x *= o.x; y *= o.y; z *= o.z; return *this; }
    constexpr Vec3& operator*=(T s) { x *= s; y *= s; z *= s; return *this; }
    constexpr bool operator==(const Vec3&) const = default;
};

template <typename T>
struct Vec4 {
    T x{}, y{}, z{}, w{};
    constexpr Vec4() = default;
    constexpr explicit Vec4(T s) : x(s), y(s), z(s), w(s) {}
    constexpr Vec4(T x_, T y_, T z_, T w_) : x(x_), y(y_), z(z_), w(w_) {}
    constexpr Vec4(const Vec3<T>& v, T w_) : x(v.x), y(v.y), z(v.z), w(w_) {}
    constexpr Vec3<T> xyz() const { return {x, y, z}; }
    constexpr T operator[](int i) const { return i == 0 ? x : (i == 1 ? y : (i == 2 ? z : w)); }
    constexpr bool operator==(const Vec4&) const = default;
};

using Vec2f = Vec2<float>;
using Vec3f = Vec3<float>;
using Vec3d = Vec3<double>;
using Vec4f = Vec4<float>;
using Color = Vec3f;  ///< linear RGB (scene-linear Rec.709)

template <typename T> constexpr Vec3<T> operator*(T s, const Vec3<T>& v) { return v * s; }
template <typename T> constexpr T dot(const Vec3<T>& a, const Vec3<T>& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
template <typename T> constexpr Vec3<T> cross(const Vec3<T>& a, const Vec3<T>& b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
template <typename T> inline T length(const Vec3<T>& v) { return std::sqrt(dot(v, v)); }
/// Unit vector along v; the zero vector stays zero (never NaN).
template <typename T> inline Vec3<T> normalize(const Vec3<T>& v) {
    T l = length(v);
    return l > T(0) ? v / l : Vec3<T>(T(0));
}
template <typename T> constexpr Vec3<T> vmin(const Vec3<T>& a, const Vec3<T>& b) {
    return {std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)};
}
template <typename T> constexpr Vec3<T> vmax(const Vec3<T>& a, const Vec3<T>& b) {
    return {std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)};
}
template <typename T> constexpr T max_component(const Vec3<T>& v) { return std::max(v.x, std::max(v.y, v.z)); }
/// Largest absolute coordinate.
template <typename T> inline T max_abs(const Vec3<T>& v) { return std::max(std::fabs(v.x), std::max(std::fabs(v.y), std::fabs(v.z))); }
template <typename T> constexpr Vec3<T> lerp(const Vec3<T>& a, const Vec3<T>& b, T t) { return a * (T(1) - t) + b * t; }
template <typename T> inline bool is_finite(const Vec3<T>& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}
inline bool is_black(const Color& c) { return c.x <= 0.f && c.y <= 0.f && c.z <= 0.f; }
/// Rec. 709 luminance of linear RGB, in double (shares and sums of power).
inline double luminance(const Color& c) { return 0.2126 * double(c.x) + 0.7152 * double(c.y) + 0.0722 * double(c.z); }

/// Axis-aligned bounding box; default-constructed boxes are empty.
template <typename T>
struct Bounds3 {
    Vec3<T> lo{std::numeric_limits<T>::infinity()};
    Vec3<T> hi{-std::numeric_limits<T>::infinity()};
    bool empty() const { return lo.x > hi.x || lo.y > hi.y || lo.z > hi.z; }
    void extend(const Vec3<T>& p) { lo = vmin(lo, p); hi = vmax(hi, p); }
    void extend(const Bounds3& b) { lo = vmin(lo, b.lo); hi = vmax(hi, b.hi); }
    Vec3<T> center() const { return (lo + hi) * T(0.5); }
    Vec3<T> diagonal() const { return hi - lo; }
};
using Bounds3f = Bounds3<float>;
using Bounds3d = Bounds3<double>;

/// Row-major 4x4 double matrix for affine transforms: p' = M * [p, 1].
struct Mat4d {
    std::array<double, 16> m{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};

    static Mat4d identity() { return {}; }
    double operator()(int r, int c) const { return m[size_t(r * 4 + c)]; }
    double& operator()(int r, int c) { return m[size_t(r * 4 + c)]; }
    bool operator==(const Mat4d&) const = default;

    Mat4d operator*(const Mat4d& b) const {
        Mat4d r;
        for (int i = 0; i < 4; ++i)
            for (int j = 0; j < 4; ++j) {
                double s = 0;
                for (int k = 0; k < 4; ++k) s += (*this)(i, k) * b(k, j);
                r(i, j) = s;
            }
        return r;
    }
    Vec3d apply_point(const Vec3d& p) const {
        return {m[0] * p.x + m[1] * p.y + m[2] * p.z + m[3], m[4] * p.x + m[5] * p.y + m[6] * p.z + m[7],
                m[8] * p.x + m[9] * p.y + m[10] * p.z + m[11]};
    }
    Vec3d apply_vector(const Vec3d& v) const {
        return {m[0] * v.x + m[1] * v.y + m[2] * v.z, m[4] * v.x + m[5] * v.y + m[6] * v.z,
                m[8] * v.x + m[9] * v.y + m[10] * v.z};
    }
    /// Determinant of the upper-left 3x3 block (negative = the transform mirrors).
    double det3() const {
        return m[0] * (m[5] * m[10] - m[6] * m[9]) - m[1] * (m[4] * m[10] - m[6] * m[8]) +
               m[2] * (m[4] * m[9] - m[5] * m[8]);
    }
    /// Inverse of an affine matrix (bottom row 0 0 0 1); singular input gives identity-free zeros.
    Mat4d inverse_affine() const {
        Mat4d r;
        double d = det3();
        double inv = d != 0 ? 1.0 / d : 0.0;
        r(0, 0) = (m[5] * m[10] - m[6] * m[9]) * inv;
        r(0, 1) = (m[2] * m[9] - m[1] * m[10]) * inv;
        r(0, 2) = (m[1] * m[6] - m[2] * m[5]) * inv;
        r(1, 0) = (m[6] * m[8] - m[4] * m[10]) * inv;
        r(1, 1) = (m[0] * m[10] - m[2] * m[8]) * inv;
        r(1, 2) = (m[2] * m[4] - m[0] * m[6]) * inv;
        r(2, 0) = (m[4] * m[9] - m[5] * m[8]) * inv;
        r(2, 1) = (m[1] * m[8] - m[0] * m[9]) * inv;
        r(2, 2) = (m[0] * m[5] - m[1] * m[4]) * inv;
        Vec3d t{m[3], m[7], m[11]};
        for (int i = 0; i < 3; ++i) r(i, 3) = -(r(i, 0) * t.x + r(i, 1) * t.y + r(i, 2) * t.z);
        r(3, 0) = r(3, 1) = r(3, 2) = 0;
        r(3, 3) = 1;
        return r;
    }
    Mat4d transposed() const {
        Mat4d r;
        for (int i = 0; i < 4; ++i)
            for (int j = 0; j < 4; ++j) r(i, j) = (*this)(j, i);
        return r;
    }
    static Mat4d translate(const Vec3d& t) {
        Mat4d r;
        r(0, 3) = t.x; r(1, 3) = t.y; r(2, 3) = t.z;
        return r;
    }
    static Mat4d scale(const Vec3d& s) {
        Mat4d r;
        r(0, 0) = s.x; r(1, 1) = s.y; r(2, 2) = s.z;
        return r;
    }
    /// Rotation from a unit quaternion (x, y, z, w), glTF convention.
    static Mat4d rotate(double x, double y, double z, double w) {
        Mat4d r;
        r(0, 0) = 1 - 2 * (y * y + z * z); r(0, 1) = 2 * (x * y - z * w);     r(0, 2) = 2 * (x * z + y * w);
        r(1, 0) = 2 * (x * y + z * w);     r(1, 1) = 1 - 2 * (x * x + z * z); r(1, 2) = 2 * (y * z - x * w);
        r(2, 0) = 2 * (x * z - y * w);     r(2, 1) = 2 * (y * z + x * w);     r(2, 2) = 1 - 2 * (x * x + y * y);
        return r;
    }
    bool is_finite() const {
        for (double v : m)
            if (!std::isfinite(v)) return false;
        return true;
    }
};

/// The box around the 8 transformed corners of `b` (exact in double for an affine map up to the
/// corners' rounding); an empty box stays empty.
inline Bounds3d transform_bounds(const Mat4d& m, const Bounds3d& b) {
    Bounds3d out;
    if (b.empty()) return out;
    for (int c = 0; c < 8; ++c)
        out.extend(m.apply_point({(c & 1) ? b.hi.x : b.lo.x, (c & 2) ? b.hi.y : b.lo.y, (c & 4) ? b.hi.z : b.lo.z}));
    return out;
}

constexpr float kPi = 3.14159265358979323846f;
constexpr double kPiD = 3.14159265358979323846;
constexpr float kInfinity = std::numeric_limits<float>::infinity();

}  // namespace whitted
