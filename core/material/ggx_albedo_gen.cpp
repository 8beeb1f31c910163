// Writes core/material/ggx_albedo_table.cpp and ggx_albedo_schlick_table.cpp (see ggx_albedo.h for
// what the tables hold):
//   build/core/ggx_albedo_gen > core/material/ggx_albedo_table.cpp
//   build/core/ggx_albedo_gen schlick > core/material/ggx_albedo_schlick_table.cpp
// Each entry is an adaptive quadrature in double, written apart from ggx.h, so that the tests that
// hold the table against quadratures of the BSDF's own lobe compare independent computations.
//
// Over the half vector h, with dw_i = 4 (wo.h) dw_h,
//   e(mu) = integral of D(h) cos(theta_h) * G2(wo, wi) (wo.h) / (mu cos(theta_h)) dw_h,
// and D(h) cos(theta_h) dw_h = dw dphi / (2 pi) for w = 1 / (1 + tan^2(theta_h) / alpha^2), so
// the integrand in (w, phi) is smooth however small alpha is. G2 / mu is written
// 1 / (mu (1 + Lambda_i) + mu Lambda_o), finite at the horizon (mu = 0 is computed, not a limit).
//
// The horizon is not a cut inside the integrand but a limit of integration: with wo in the xz
// plane, wi = 2 (wo.h) h - wo is above the surface where cos(phi) > -cot(2 theta_h) / tan(theta_o),
// so every phi is in for theta_h < pi/4 - theta_o/2, none for theta_h > pi/4 + theta_o/2, and a
// symmetric interval |phi| < phi_max between. The w integral is split at those two angles and
// both integrals are adaptive Gauss-Kronrod (7/15 points), so no rule straddles a kink.
// (An earlier generator used a fixed rule with the horizon as an indicator inside it; it was off
// by up to 0.012 at mu = 2.5e-4 against a 20-digit mpmath quadrature.)
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

#include "core/material/ggx_albedo.h"

namespace {

constexpr int kN = pt::kGgxAlbedoSize;
constexpr double kPi = 3.14159265358979323846;
constexpr double kMinAlpha = 1e-4;  // kMinGgxAlpha
constexpr double kTolerance = 1e-10;

using Pair = std::array<double, 2>;  // (e, e_schlick), integrated together

// Gauss-Kronrod 7/15 nodes and weights on [-1, 1] (Kronrod nodes; every other one is Gauss).
const double kXk[8] = {0.991455371120812639, 0.949107912342758525, 0.864864423359769073, 0.741531185599394440,
                       0.586087235467691130, 0.405845151377397167, 0.207784955007898468, 0.0};
const double kWk[8] = {0.022935322010529225, 0.063092092629978553, 0.104790010322250184, 0.140653259715525919,
                       0.169004726639267903, 0.190350578064785410, 0.204432940075298892, 0.209482141084727828};
const double kWg[4] = {0.129484966168869693, 0.279705391489276668, 0.381830050505118945, 0.417959183673469388};

// Adaptive Gauss-Kronrod of a pair-valued f over [a, b] to an absolute tolerance.
Pair integrate(const std::function<Pair(double)>& f, double a, double b, double tolerance, int depth = 0) {
  double c = 0.5 * (a + b), h = 0.5 * (b - a);
  Pair kronrod{0, 0}, gauss{0, 0};
  for (int i = 0; i < 8; ++i) {
    Pair lo = f(c - h * kXk[i]);
    Pair hi = i < 7 ? f(c + h * kXk[i]) : Pair{0, 0};
    for (int k = 0; k < 2; ++k) {
      double sum = lo[k] + hi[k];
      kronrod[k] += kWk[i] * sum;
      if (i % 2 == 1) gauss[k] += kWg[i / 2] * sum;  // i = 7 is the centre: hi is 0 there
    }
  }
  double error = std::max(std::abs(kronrod[0] - gauss[0]), std::abs(kronrod[1] - gauss[1])) * h;
  if (error <= tolerance || depth >= 40 || h < 1e-15) return {kronrod[0] * h, kronrod[1] * h};
  Pair left = integrate(f, a, c, 0.5 * tolerance, depth + 1);
  Pair right = integrate(f, c, b, 0.5 * tolerance, depth + 1);
  return {left[0] + right[0], left[1] + right[1]};
}

double lambda_of_cos(double alpha, double cos_t) {
  double t2 = std::max(0.0, 1 - cos_t * cos_t) / (cos_t * cos_t);
  return 0.5 * (std::sqrt(1 + alpha * alpha * t2) - 1);
}

// e and e_schlick of single-scattering GGX at mu = cos(theta_o), width alpha.
Pair albedo(double alpha, double mu) {
  double so = std::sqrt(std::max(0.0, 1 - mu * mu));
  // mu * Lambda(wo) = 0.5 (sqrt(mu^2 + alpha^2 so^2) - mu), without dividing by mu.
  double mu_lambda_o = 0.5 * (std::sqrt(mu * mu + alpha * alpha * so * so) - mu);
  double theta_o = std::atan2(so, mu);
  auto w_of = [&](double theta_h) {
    double t = std::tan(theta_h) / alpha;
    return 1 / (1 + t * t);
  };
  // Integrand over phi at fixed h elevation; dphi / (2 pi), doubled for the symmetric half.
  auto at_w = [&](double w) -> Pair {
    if (w <= 0) return {0, 0};
    double t2 = alpha * alpha * (1 / w - 1);  // tan^2(theta_h)
    double ch = 1 / std::sqrt(1 + t2), sh = std::sqrt(t2) * ch;
    double phi_max = kPi;
    if (so > 0) {
      double c = -mu * (2 * ch * ch - 1) / (so * 2 * sh * ch);  // -cot(2 theta_h) / tan(theta_o)
      if (c >= 1) return {0, 0};
      if (c > -1) phi_max = std::acos(c);
    } else if (2 * ch * ch - 1 <= 0) {
      return {0, 0};
    }
    auto at_phi = [&](double phi) -> Pair {
      double oh = so * sh * std::cos(phi) + mu * ch;
      double wi_z = 2 * oh * ch - mu;
      if (oh <= 0 || wi_z <= 0) return {0, 0};
      double value = oh / (ch * (mu * (1 + lambda_of_cos(alpha, wi_z)) + mu_lambda_o)) / kPi;
      double m = 1 - oh, m2 = m * m;
      return {value, value * m2 * m2 * m};
    };
    return integrate(at_phi, 0, phi_max, kTolerance);
  };
  double w_none = theta_o > 0 ? w_of(std::min(kPi / 4 + theta_o / 2, kPi / 2)) : w_of(kPi / 4);
  double w_all = theta_o > 0 ? w_of(kPi / 4 - theta_o / 2) : w_of(kPi / 4);
  if (theta_o >= kPi / 2) w_none = 0;
  Pair partial = w_all > w_none ? integrate(at_w, w_none, w_all, kTolerance) : Pair{0, 0};
  Pair whole = integrate(at_w, w_all, 1, kTolerance);
  return {partial[0] + whole[0], partial[1] + whole[1]};
}

// 2 integral_0^1 f(mu) mu dmu of the interpolant: linear in x = sqrt(mu) between entries, so
// mu = x^2 and the integral is 4 integral f(x) x^3 dx, a polynomial of degree 4 on each interval
// (Gauss-Legendre with 4 points is exact for it).
double cosine_average(const std::vector<double>& f) {
  static const double x4[4] = {-0.8611363115940526, -0.3399810435848563, 0.3399810435848563, 0.8611363115940526};
  static const double w4[4] = {0.3478548451374538, 0.6521451548625461, 0.6521451548625461, 0.3478548451374538};
  double sum = 0, h = 1.0 / (kN - 1);
  for (int i = 0; i + 1 < kN; ++i) {
    for (int g = 0; g < 4; ++g) {
      double s = 0.5 + 0.5 * x4[g], x = (i + s) * h;
      sum += 4 * (f[i] * (1 - s) + f[i + 1] * s) * x * x * x * 0.5 * w4[g] * h;
    }
  }
  return sum;
}

// Ten values a line, six decimals (the tables' interpolation error is 1e-3; the rounding 5e-7).
void print_values(const std::vector<double>& v, const char* indent) {
  for (size_t i = 0; i < v.size(); ++i) {
    std::printf("%s%.6ff,", i % 10 == 0 ? indent : " ", v[i]);
    if (i % 10 == 9 || i + 1 == v.size()) std::printf("\n");
  }
}

void print_table(const char* name, const std::vector<std::vector<double>>& t) {
  std::printf("const float %s[kGgxAlbedoSize][kGgxAlbedoSize] = {\n", name);
  for (const auto& row : t) {
    std::printf("    {\n");
    print_values(row, "        ");
    std::printf("    },\n");
  }
  std::printf("};\n");
}

void print_row(const char* name, const std::vector<double>& r) {
  std::printf("const float %s[kGgxAlbedoSize] = {\n", name);
  print_values(r, "    ");
  std::printf("};\n");
}

}  // namespace

// "e" (the default) prints ggx_albedo_table.cpp, "schlick" ggx_albedo_schlick_table.cpp: two
// files, so that neither is over 600 lines. Both runs compute both tables.
int main(int argc, char** argv) {
  bool schlick = argc > 1 && std::string(argv[1]) == "schlick";
  std::vector<std::vector<double>> e(kN, std::vector<double>(kN)), e5 = e;
  std::vector<double> avg(kN), avg5(kN);
  for (int r = 0; r < kN; ++r) {
    double roughness = pt::ggx_albedo_node(r);
    double alpha = std::max(roughness * roughness, kMinAlpha);
    for (int m = 0; m < kN; ++m) {
      Pair p = albedo(alpha, pt::ggx_albedo_node(m));
      e[r][m] = p[0];
      e5[r][m] = p[1];
    }
    avg[r] = cosine_average(e[r]);
    avg5[r] = cosine_average(e5[r]);
  }
  std::printf("// Generated by core/material/ggx_albedo_gen.cpp%s; do not edit (ggx_albedo.h says what it holds).\n",
              schlick ? " schlick" : "");
  std::printf("#include \"core/material/ggx_albedo.h\"\n\nnamespace pt {\n\n");
  print_table(schlick ? "kGgxAlbedoSchlick" : "kGgxAlbedo", schlick ? e5 : e);
  print_row(schlick ? "kGgxAlbedoSchlickAvg" : "kGgxAlbedoAvg", schlick ? avg5 : avg);
  std::printf("\n}  // namespace pt\n");
  return 0;
}
