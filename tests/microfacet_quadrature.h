// Integrals over the directions a microfacet BSDF reflects into, taken in the coordinates of its
// half vector, where a GGX lobe of any width is smooth: the tests of
// test_unit_metallic_roughness.cpp integrate pdfs over chi-square cells and f cos over the
// hemisphere with it. Nothing here is shared with the BSDF or with the table generator
// (core/material/ggx_albedo_gen.cpp); the BSDF is only called through eval and pdf.
//
// The chart: for an outgoing direction wo (above the surface) and a GGX width alpha, a half vector
// h is given by (v, phi), v = sqrt(w), w = 1 / (1 + tan^2(theta_h) / alpha^2) in [0, 1] (v = 1 is
// the normal), and phi its azimuth measured from wo's. Then wi = 2 (wo.h) h - wo, and
//   dw_h = alpha^2 / (v^2 + alpha^2 (1 - v^2))^(3/2) dv dphi,   dw_i = 4 (wo.h) dw_h,
// so GGX's D(h) dw_h is (v^2 + alpha^2 (1 - v^2))^(1/2) / pi times a smooth function of wo.h: a
// visible-normal sampler's density is of order 1 over the whole chart. A cosine lobe, spread over
// all h, lives at v up to a few alpha with density ~1/alpha there; integrals are split at
// v = alpha 2^k so no rule straddles it.
// wi is above the surface exactly where cos(phi) > -cot(2 theta_h) / tan(theta_o) (all phi below
// theta_h = pi/4 - theta_o/2, none above pi/4 + theta_o/2): the horizon is a limit of the phi
// integral, not a jump inside it.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "core/math/vec.h"

namespace pt::test {

constexpr double kPiQ = 3.14159265358979323846;

// A direction `degrees` from the normal (+z), off the coordinate planes (azimuth atan(0.8 / 0.6)).
inline Vec3f at_angle(double degrees) {
  double t = degrees * kPiQ / 180.0;
  return normalize(Vec3f(static_cast<float>(std::sin(t) * 0.6), static_cast<float>(std::sin(t) * 0.8), static_cast<float>(std::cos(t))));
}

template <int N>
using Values = std::array<double, N>;

struct D3 {
  double x = 0, y = 0, z = 0;
};
inline double dot3(const D3& a, const D3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline Vec3f to_float(const D3& d) { return {static_cast<float>(d.x), static_cast<float>(d.y), static_cast<float>(d.z)}; }

class HalfVectorChart {
 public:
  HalfVectorChart(const Vec3f& wo_f, double alpha) : alpha_(alpha) {
    double l = std::sqrt(double(wo_f.x) * wo_f.x + double(wo_f.y) * wo_f.y + double(wo_f.z) * wo_f.z);
    wo_ = {wo_f.x / l, wo_f.y / l, wo_f.z / l};
    so_ = std::sqrt(wo_.x * wo_.x + wo_.y * wo_.y);
    phi_o_ = so_ > 0 ? std::atan2(wo_.y, wo_.x) : 0.0;
  }
  double alpha() const { return alpha_; }

  struct Point {
    D3 h, wi;
    double wo_h = 0;
    double jacobian = 0;  // dw_i / (dv dphi)
  };
  Point at(double v, double phi) const {
    double q = std::sqrt(v * v + alpha_ * alpha_ * (1 - v * v));
    double ch = v / q, sh = alpha_ * std::sqrt(std::max(0.0, 1 - v * v)) / q;
    Point p;
    p.h = {sh * std::cos(phi + phi_o_), sh * std::sin(phi + phi_o_), ch};
    p.wo_h = dot3(wo_, p.h);
    p.wi = {2 * p.wo_h * p.h.x - wo_.x, 2 * p.wo_h * p.h.y - wo_.y, 2 * p.wo_h * p.h.z - wo_.z};
    p.jacobian = 4 * p.wo_h * alpha_ * alpha_ / (q * q * q);
    return p;
  }
  // wi is above the surface for |phi| < phi_max(v) (0: nowhere, pi: everywhere).
  double phi_max(double v) const {
    double q = std::sqrt(v * v + alpha_ * alpha_ * (1 - v * v));
    double ch = v / q, sh = alpha_ * std::sqrt(std::max(0.0, 1 - v * v)) / q;
    double cos2 = ch * ch - sh * sh, sin2 = 2 * sh * ch;
    if (so_ <= 0) return cos2 > 0 ? kPiQ : 0.0;
    double c = -wo_.z * cos2 / (so_ * sin2);
    if (!(sin2 > 0)) return cos2 > 0 ? kPiQ : 0.0;
    if (c >= 1) return 0.0;
    return c <= -1 ? kPiQ : std::acos(c);
  }
  // The chart coordinates of a direction wi above the surface (through h = normalize(wo + wi)).
  void coords(const Vec3f& wi_f, double& v, double& phi) const {
    D3 h{wo_.x + wi_f.x, wo_.y + wi_f.y, wo_.z + wi_f.z};
    double t2 = h.x * h.x + h.y * h.y;  // the length of h cancels in v
    v = alpha_ * h.z / std::sqrt(alpha_ * alpha_ * h.z * h.z + t2);
    phi = std::atan2(h.y, h.x) - phi_o_;
    if (phi <= -kPiQ) phi += 2 * kPiQ;
    if (phi > kPiQ) phi -= 2 * kPiQ;
  }

  // Integral of g(wi) dw_i over the chart rectangle [v0, v1] x [phi0, phi1] (phi within [-pi, pi])
  // where wi is above the surface; g: const Vec3f& wi -> Values<N>. The phi range at each v is
  // mapped onto s in [0, 1] (so the horizon is an edge, not a jump), and (sigma, s) is integrated by
  // adaptive 2D cubature: a 6x6 Gauss-Legendre rule on a rectangle against the same rule on its
  // four quarters, recursing where they differ by more than abs_tol + rel_tol |estimate|.
  template <int N, class G>
  Values<N> integrate(const G& g, double v0, double v1, double phi0, double phi1, double abs_tol, double rel_tol) const {
    // In sigma = sqrt(1 - v), v = 1 - sigma^2: h's tilt from the normal goes as sqrt(1 - v), so
    // in v the integrand has a square-root singularity at the pole; in sigma it is smooth.
    auto value = [&](double sigma, double s) {
      Values<N> out{};
      double v = 1 - sigma * sigma;
      double m = phi_max(v);
      double a = std::max(phi0, -m), b = std::min(phi1, m);
      if (!(b > a)) return out;
      Point p = at(v, a + s * (b - a));
      if (!(p.wi.z > 0) || !(p.wo_h > 0)) return out;
      Values<N> x = g(to_float(p.wi));
      for (int k = 0; k < N; ++k) out[k] = x[k] * p.jacobian * (b - a) * 2 * sigma;
      return out;
    };
    // Pieces in v that no kink crosses: split at v = alpha 2^k (k >= -4), where a cosine lobe's
    // mass changes scale, and where phi_max(v) (increasing in v) reaches pi, phi0 or phi1.
    std::vector<double> cuts{v0, v1};
    for (double edge = alpha_ / 16; edge < v1; edge *= 2) cuts.push_back(edge);
    for (double target : {kPiQ - 1e-12, std::abs(phi0), std::abs(phi1)}) {
      double lo = 0, hi = 1;
      if (!(phi_max(hi) > target) || phi_max(lo) > target) continue;
      for (int i = 0; i < 60; ++i) {
        double mid = 0.5 * (lo + hi);
        (phi_max(mid) > target ? hi : lo) = mid;
      }
      cuts.push_back(lo);
      cuts.push_back(hi);
    }
    std::sort(cuts.begin(), cuts.end());
    Values<N> sum{};
    for (size_t i = 0; i + 1 < cuts.size(); ++i) {
      double lo = std::max(cuts[i], v0), hi = std::min(cuts[i + 1], v1);
      if (!(hi > lo)) continue;
      // sigma = s0 + (s1 - s0) (3x^2 - 2x^3): flat at both ends of the piece, where phi_max(v) has
      // square-root behaviour (wi reaching the horizon at phi = 0, or at every phi), so the
      // integrand is smooth in x.
      double s0 = std::sqrt(1 - hi), s1 = std::sqrt(1 - lo);
      auto in_x = [&](double x, double s) {
        Values<N> out = value(s0 + (s1 - s0) * x * x * (3 - 2 * x), s);
        for (int k = 0; k < N; ++k) out[k] *= (s1 - s0) * 6 * x * (1 - x);
        return out;
      };
      long budget = kMaxRules;
      Values<N> part = adapt<N>(in_x, 0, 1, 0, 1, rule<N>(in_x, 0, 1, 0, 1), abs_tol, rel_tol, 10, budget);
      for (int k = 0; k < N; ++k) sum[k] += part[k];
    }
    return sum;
  }

  // Rectangles accepted although their estimates still differed by more than the tolerance (at
  // the depth limit or past the budget of kMaxRules rules per piece): where float rounding of
  // the BSDF's own directions is a visible fraction of its lobe, refinement cannot converge.
  long unconverged() const { return unconverged_; }
  static constexpr long kMaxRules = 2000;

 private:
  template <int N, class F>
  static Values<N> rule(const F& f, double x0, double x1, double y0, double y1) {
    static const double x6[6] = {-0.932469514203152, -0.661209386466265, -0.238619186083197,
                                 0.238619186083197,  0.661209386466265,  0.932469514203152};
    static const double w6[6] = {0.171324492379170, 0.360761573048139, 0.467913934572691,
                                 0.467913934572691, 0.360761573048139, 0.171324492379170};
    double cx = 0.5 * (x0 + x1), hx = 0.5 * (x1 - x0), cy = 0.5 * (y0 + y1), hy = 0.5 * (y1 - y0);
    Values<N> sum{};
    for (int i = 0; i < 6; ++i) {
      for (int j = 0; j < 6; ++j) {
        Values<N> v = f(cx + hx * x6[i], cy + hy * x6[j]);
        for (int k = 0; k < N; ++k) sum[k] += w6[i] * w6[j] * v[k];
      }
    }
    for (int k = 0; k < N; ++k) sum[k] *= hx * hy;
    return sum;
  }
  template <int N, class F>
  Values<N> adapt(const F& f, double x0, double x1, double y0, double y1, const Values<N>& whole, double abs_tol,
                         double rel_tol, int depth, long& budget) const {
    budget -= 4;
    double xm = 0.5 * (x0 + x1), ym = 0.5 * (y0 + y1);
    Values<N> q[4] = {rule<N>(f, x0, xm, y0, ym), rule<N>(f, xm, x1, y0, ym), rule<N>(f, x0, xm, ym, y1),
                      rule<N>(f, xm, x1, ym, y1)};
    Values<N> sum{};
    bool converged = true;
    for (int k = 0; k < N; ++k) {
      sum[k] = q[0][k] + q[1][k] + q[2][k] + q[3][k];
      if (std::abs(sum[k] - whole[k]) > abs_tol + rel_tol * std::abs(sum[k])) converged = false;
    }
    if (converged || depth <= 0 || budget <= 0) {
      if (!converged) ++unconverged_;
      return sum;
    }
    double xs[3] = {x0, xm, x1}, ys[3] = {y0, ym, y1};
    Values<N> out{};
    for (int i = 0; i < 4; ++i) {
      Values<N> part = adapt<N>(f, xs[i % 2], xs[i % 2 + 1], ys[i / 2], ys[i / 2 + 1], q[i], 0.25 * abs_tol, rel_tol, depth - 1, budget);
      for (int k = 0; k < N; ++k) out[k] += part[k];
    }
    return out;
  }

  double alpha_;
  D3 wo_;
  double so_ = 0, phi_o_ = 0;
  mutable long unconverged_ = 0;
};

}  // namespace pt::test
