// Affine transforms: applied to objects at load time, and held by instances (core/geometry/instance.h),
// whose rays are taken into object space by the inverse.
#pragma once
#include <cmath>

#include "core/math/vec.h"

namespace pt {

struct Transform {
  float m[3][4] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}};

  static Transform translate(const Vec3f& t) {
    Transform r;
    r.m[0][3] = t.x; r.m[1][3] = t.y; r.m[2][3] = t.z;
    return r;
  }
  static Transform scale(const Vec3f& s) {
    Transform r;
    r.m[0][0] = s.x; r.m[1][1] = s.y; r.m[2][2] = s.z;
    return r;
  }
  // Rotation about a coordinate axis (0=x, 1=y, 2=z) by degrees, right-handed.
  static Transform rotate_axis(int axis, float degrees) {
    Transform r;
    float a = degrees * kPi / 180.0f, c = std::cos(a), s = std::sin(a);
    int i = (axis + 1) % 3, j = (axis + 2) % 3;
    r.m[i][i] = c; r.m[i][j] = -s;
    r.m[j][i] = s; r.m[j][j] = c;
    return r;
  }
  Transform operator*(const Transform& b) const {  // apply b first, then *this
    Transform r;
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 4; ++j) {
        r.m[i][j] = m[i][0] * b.m[0][j] + m[i][1] * b.m[1][j] + m[i][2] * b.m[2][j] + (j == 3 ? m[i][3] : 0.0f);
      }
    }
    return r;
  }
  Vec3f point(const Vec3f& p) const {
    return {m[0][0] * p.x + m[0][1] * p.y + m[0][2] * p.z + m[0][3],
            m[1][0] * p.x + m[1][1] * p.y + m[1][2] * p.z + m[1][3],
            m[2][0] * p.x + m[2][1] * p.y + m[2][2] * p.z + m[2][3]};
  }
  Vec3f vector(const Vec3f& v) const {
    return {m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z, m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
            m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z};
  }
  // The linear part, transposed, times v: the inverse's takes a gradient (of a function over the
  // target space) back to the source space.
  Vec3f transposed_vector(const Vec3f& v) const {
    return {m[0][0] * v.x + m[1][0] * v.y + m[2][0] * v.z, m[0][1] * v.x + m[1][1] * v.y + m[2][1] * v.z,
            m[0][2] * v.x + m[1][2] * v.y + m[2][2] * v.z};
  }
  // Normals transform by the inverse transpose: the cofactor matrix, up to a positive scale.
  Vec3f normal(const Vec3f& n) const {
    Vec3f c0{m[0][0], m[1][0], m[2][0]}, c1{m[0][1], m[1][1], m[2][1]}, c2{m[0][2], m[1][2], m[2][2]};
    Vec3f r0 = cross(c1, c2), r1 = cross(c2, c0), r2 = cross(c0, c1);
    float det = dot(c0, r0);
    Vec3f out = r0 * n.x + r1 * n.y + r2 * n.z;
    return det < 0 ? -out : out;
  }
  // The inverse, computed in double (the adjugate over the determinant) so that taking a ray into an
  // instance and its hit back out loses no more than float rounding. Only for an invertible transform.
  Transform inverse() const {
    double a[3][3];
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) a[i][j] = m[i][j];
    }
    double c[3][3];  // c[i][j]: cofactor of a[j][i], so that inverse = c / det
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) {
        int r0 = (j + 1) % 3, r1 = (j + 2) % 3, c0 = (i + 1) % 3, c1 = (i + 2) % 3;
        c[i][j] = a[r0][c0] * a[r1][c1] - a[r0][c1] * a[r1][c0];
      }
    }
    double det = a[0][0] * c[0][0] + a[0][1] * c[1][0] + a[0][2] * c[2][0];
    Transform r;
    for (int i = 0; i < 3; ++i) {
      double t = 0;
      for (int j = 0; j < 3; ++j) {
        double v = c[i][j] / det;
        r.m[i][j] = static_cast<float>(v);
        t -= v * m[j][3];
      }
      r.m[i][3] = static_cast<float>(t);
    }
    return r;
  }
  bool flips_handedness() const {
    Vec3f c0{m[0][0], m[1][0], m[2][0]}, c1{m[0][1], m[1][1], m[2][1]}, c2{m[0][2], m[1][2], m[2][2]};
    return dot(c0, cross(c1, c2)) < 0;
  }
};

}  // namespace pt
