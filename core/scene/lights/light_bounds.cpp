#include "core/scene/lights/light_bounds.h"

namespace pt {
namespace {

float safe_sqrt(float x) { return std::sqrt(std::max(0.0f, x)); }
float safe_acos(float x) { return std::acos(std::clamp(x, -1.0f, 1.0f)); }

}  // namespace

LightBounds merge(const LightBounds& a, const LightBounds& b) {
  if (a.empty()) return b;
  if (b.empty()) return a;
  LightBounds m;
  m.box = a.box;
  m.box.expand(b.box);
  m.phi = a.phi + b.phi;
  m.cos_e = std::min(a.cos_e, b.cos_e);
  // The cones: if one holds the other, it is the union.
  float theta_a = safe_acos(a.cos_o), theta_b = safe_acos(b.cos_o);
  float theta_d = safe_acos(dot(a.axis, b.axis));
  if (std::min(theta_d + theta_b, kPi) <= theta_a) {
    m.axis = a.axis, m.cos_o = a.cos_o;
    return m;
  }
  if (std::min(theta_d + theta_a, kPi) <= theta_b) {
    m.axis = b.axis, m.cos_o = b.cos_o;
    return m;
  }
  // Else the cone spanning both: half-angle (theta_a + theta_d + theta_b) / 2, its axis a's turned
  // toward b's by that less theta_a.
  float theta_o = 0.5f * (theta_a + theta_d + theta_b);
  Vec3f k = cross(a.axis, b.axis);
  float k_len = length(k);
  if (theta_o >= kPi || !(k_len > 0)) {
    m.axis = a.axis, m.cos_o = -1.0f;
    return m;
  }
  k = k / k_len;
  float turn = theta_o - theta_a;
  // Rodrigues' rotation of a.axis about k (perpendicular to it) by `turn`.
  m.axis = normalize(a.axis * std::cos(turn) + cross(k, a.axis) * std::sin(turn));
  m.cos_o = std::cos(theta_o);
  return m;
}

float orientation_measure(const LightBounds& b) {
  float theta_o = safe_acos(b.cos_o), theta_e = safe_acos(b.cos_e);
  float theta_w = std::min(theta_o + theta_e, kPi);
  float sin_o = safe_sqrt(1.0f - b.cos_o * b.cos_o);
  return 2.0f * kPi * (1.0f - b.cos_o) +
         0.5f * kPi * (2.0f * theta_w * sin_o - std::cos(theta_o - 2.0f * theta_w) - 2.0f * theta_o * sin_o + b.cos_o);
}

LightCone light_cone(const LightBounds& b) {
  LightCone c;
  c.center = b.box.center();
  c.radius2 = 0.25f * length_squared(b.box.extent());
  c.radius = std::sqrt(c.radius2);
  c.axis = b.axis;
  c.phi = b.phi;
  c.cos_o = b.cos_o;
  c.sin_o = safe_sqrt(1.0f - b.cos_o * b.cos_o);
  c.cos_e = b.cos_e;
  if (b.cos_o >= 1.0f && b.cos_e >= 0.0f) {
    Vec3f half = b.box.extent() * 0.5f;
    c.behind = std::abs(b.axis.x) * half.x + std::abs(b.axis.y) * half.y + std::abs(b.axis.z) * half.z + 1e-5f * c.radius;
  }
  return c;
}

}  // namespace pt
