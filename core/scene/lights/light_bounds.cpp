#include "core/scene/lights/light_bounds.h"

namespace pt {
namespace {

constexpr float kMaxImportance = 1e30f;  // two siblings' importances still add up to a finite sum

// cos and sin of max(0, a - b) from the cosines and sines of a and b (angles in [0, pi]).
float cos_sub_clamped(float sin_a, float cos_a, float sin_b, float cos_b) {
  if (cos_a > cos_b) return 1.0f;  // a < b
  return cos_a * cos_b + sin_a * sin_b;
}
float sin_sub_clamped(float sin_a, float cos_a, float sin_b, float cos_b) {
  if (cos_a > cos_b) return 0.0f;
  return sin_a * cos_b - cos_a * sin_b;
}
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

float importance(const LightBounds& b, const Vec3f& p, const Vec3f& n) {
  if (!(b.phi > 0)) return 0.0f;
  Vec3f pc = b.box.center();
  Vec3f to_p = p - pc;
  float dist2 = length_squared(to_p);
  float r2 = 0.25f * length_squared(b.box.extent());  // the box's bounding sphere
  float d2 = std::max({dist2, r2, 1e-30f});
  // The cone of directions from p into the bounding sphere: theta_b (all of them from inside).
  float cos_b = -1.0f, sin_b = 0.0f;
  bool outside = dist2 > r2;
  Vec3f wi = outside ? to_p / std::sqrt(dist2) : Vec3f(0.0f);
  if (outside) {
    float sin2_b = r2 / dist2;
    sin_b = std::sqrt(sin2_b);
    cos_b = safe_sqrt(1.0f - sin2_b);
  }
  float cos_p = 1.0f;  // cos theta': the smallest angle between an emitter's normal and the direction to p
  if (outside) {
    float cos_w = dot(b.axis, wi), sin_w = safe_sqrt(1.0f - cos_w * cos_w);
    float sin_o = safe_sqrt(1.0f - b.cos_o * b.cos_o);
    float cos_x = cos_sub_clamped(sin_w, cos_w, sin_o, b.cos_o);
    float sin_x = sin_sub_clamped(sin_w, cos_w, sin_o, b.cos_o);
    cos_p = cos_sub_clamped(sin_x, cos_x, sin_b, cos_b);
  }
  if (cos_p <= b.cos_e) return 0.0f;
  float result = b.phi * cos_p / d2;
  if (outside && (n.x != 0 || n.y != 0 || n.z != 0)) {
    // The smallest angle between n and a direction from p into the sphere.
    float cos_i = -dot(n, wi), sin_i = safe_sqrt(1.0f - cos_i * cos_i);
    float cos_ip = cos_sub_clamped(sin_i, cos_i, sin_b, cos_b);
    if (cos_ip <= 0) return 0.0f;
    result *= cos_ip;
  }
  return std::min(result, kMaxImportance);
}

}  // namespace pt
