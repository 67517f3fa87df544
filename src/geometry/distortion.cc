#include "saccade/geometry/distortion.h"

#include <fmt/format.h>

#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <string_view>

#include "saccade/core/error.h"

namespace saccade::geometry {
namespace {

// cv::fisheye::projectPoints uses distortion factor 1 below this normalized radius.
constexpr double kFisheyeSmallRadius = 1e-8;
// A 2x2 Jacobian whose determinant is below this fraction of its squared largest entry is
// treated as singular: a Newton step there is dominated by rounding.
constexpr double kSingularJacobian = 1e-14;
// Halvings of a Newton step tried before declaring that the residual stagnates.
constexpr int kMaxStepHalvings = 40;
// Depth of the interval subdivision when proving that a polynomial is positive.
constexpr int kMaxBernsteinDepth = 24;

constexpr std::array<std::string_view, 14> kRadTanNames = {
    "k1", "k2", "p1", "p2", "k3", "k4", "k5", "k6", "s1", "s2", "s3", "s4", "tau_x", "tau_y"};

// Polynomial in s with coefficients a[0] + a[1] s + ... (at most degree 8 here).
using Poly = std::array<double, 9>;

Poly Multiply(const Poly& a, const Poly& b) {
  Poly c{};
  for (size_t i = 0; i < a.size(); ++i) {
    for (size_t j = 0; i + j < c.size(); ++j) c[i + j] += a[i] * b[j];
  }
  return c;
}

// True when the polynomial with Bernstein coefficients `b` (degree n, on some interval) is
// provably positive there: all coefficients positive, or, after de Casteljau subdivision,
// on both halves. False when it is not positive or when positivity cannot be proved within
// the depth limit (a polynomial touching zero), which is the safe answer for the callers.
bool BernsteinPositive(const Poly& b, int n, int depth) {
  if (b[0] <= 0.0 || b[n] <= 0.0) return false;  // the end values themselves
  bool all_positive = true;
  for (int k = 0; k <= n; ++k) all_positive = all_positive && b[k] > 0.0;
  if (all_positive) return true;
  if (depth >= kMaxBernsteinDepth) return false;
  // de Casteljau at t = 1/2: the left half reads the first column, the right the diagonal.
  Poly left{}, right{}, work = b;
  for (int level = 0; level <= n; ++level) {
    left[level] = work[0];
    right[n - level] = work[n - level];
    for (int k = 0; k < n - level; ++k) work[k] = 0.5 * (work[k] + work[k + 1]);
  }
  return BernsteinPositive(left, n, depth + 1) && BernsteinPositive(right, n, depth + 1);
}

// True when p(s) > 0 for every s in [0, s_max] (checked in exact arithmetic up to rounding of
// the Bernstein coefficients, not by sampling).
bool PositiveOn(const Poly& a, double s_max) {
  if (!(std::isfinite(s_max) && s_max >= 0.0)) return false;
  int n = static_cast<int>(a.size()) - 1;
  while (n > 0 && a[n] == 0.0) --n;
  // Power basis on [0, s_max] -> t in [0, 1] -> Bernstein basis.
  Poly scaled{};
  double power = 1.0;
  for (int i = 0; i <= n; ++i, power *= s_max) scaled[i] = a[i] * power;
  Poly bern{};
  for (int k = 0; k <= n; ++k) {
    double sum = 0.0;
    double ratio = 1.0;  // C(k, i) / C(n, i)
    for (int i = 0; i <= k; ++i) {
      sum += ratio * scaled[i];
      if (i < k) ratio *= static_cast<double>(k - i) / static_cast<double>(n - i);
    }
    bern[k] = sum;
  }
  return BernsteinPositive(bern, n, 0);
}

struct RadTanModel {
  double k1, k2, p1, p2, k3, k4, k5, k6;
  explicit RadTanModel(const std::vector<double>& c)
      : k1(c[0]), k2(c[1]), p1(c[2]), p2(c[3]), k3(c[4]), k4(c[5]), k5(c[6]), k6(c[7]) {}

  // Numerator and denominator of the radial factor, in s = r^2.
  Poly Numerator() const { return {1.0, k1, k2, k3}; }
  Poly Denominator() const { return {1.0, k4, k5, k6}; }

  // True when the radial part r -> r N(r^2) / D(r^2) is strictly increasing on [0, sqrt(s_max)]
  // (and D > 0 there): the region where the model is one-to-one and Undistort may answer.
  // d/dr [r N/D] = (M D - N E) / D^2 with M_i = (1 + 2i) n_i and E_i = 2i d_i.
  bool RadiallyMonotonic(double s_max) const {
    const Poly N = Numerator();
    const Poly D = Denominator();
    Poly M{}, E{};
    for (size_t i = 0; i < N.size(); ++i) {
      M[i] = (1.0 + 2.0 * static_cast<double>(i)) * N[i];
      E[i] = 2.0 * static_cast<double>(i) * D[i];
    }
    const Poly MD = Multiply(M, D);
    const Poly NE = Multiply(N, E);
    Poly Q{};
    for (size_t i = 0; i < Q.size(); ++i) Q[i] = MD[i] - NE[i];
    return PositiveOn(D, s_max) && PositiveOn(Q, s_max);
  }
};

struct FisheyeModel {
  double k1, k2, k3, k4;
  explicit FisheyeModel(const std::vector<double>& c) : k1(c[0]), k2(c[1]), k3(c[2]), k4(c[3]) {}

  // theta_d(theta), with OpenCV's order of operations (fisheye.cpp, projectPoints).
  double ThetaD(double theta) const {
    const double theta2 = theta * theta, theta3 = theta2 * theta, theta4 = theta2 * theta2,
                 theta5 = theta4 * theta, theta6 = theta3 * theta3, theta7 = theta6 * theta,
                 theta8 = theta4 * theta4, theta9 = theta8 * theta;
    return theta + k1 * theta3 + k2 * theta5 + k3 * theta7 + k4 * theta9;
  }
  // d theta_d / d theta.
  double ThetaDPrime(double theta) const {
    const double s = theta * theta;
    return 1.0 + s * (3.0 * k1 + s * (5.0 * k2 + s * (7.0 * k3 + s * 9.0 * k4)));
  }
  // theta_d is strictly increasing on [0, theta]: the invertible region.
  bool Monotonic(double theta) const {
    return PositiveOn({1.0, 3.0 * k1, 5.0 * k2, 7.0 * k3, 9.0 * k4}, theta * theta);
  }

  struct Inverse {
    double theta = 0.0;
    bool converged = false;
    int iterations = 0;
    double residual = 0.0;  // |theta_d(theta) - theta_d|
  };

  // 1D Newton on theta_d(theta) = theta_d (as cv::fisheye::undistortPoints, which starts at
  // theta = theta_d), but converged only when the residual is below tolerance, theta is a ray
  // direction (0 <= theta < pi) and theta_d is monotonic on [0, theta].
  Inverse Solve(double theta_d, double tolerance, int max_iterations) const {
    Inverse out;
    out.theta = theta_d;
    if (!std::isfinite(theta_d) || theta_d < 0.0) {
      out.residual = std::numeric_limits<double>::infinity();
      return out;
    }
    double theta = theta_d;
    double residual = std::abs(ThetaD(theta) - theta_d);
    while (residual > tolerance && out.iterations < max_iterations) {
      const double derivative = ThetaDPrime(theta);
      if (!(std::abs(derivative) > kSingularJacobian)) break;
      const double step = (ThetaD(theta) - theta_d) / derivative;
      // Halve the step while it does not reduce the residual (Newton overshoot near a fold).
      double next = theta - step;
      double next_residual = std::abs(ThetaD(next) - theta_d);
      double scale = 1.0;
      for (int h = 0; h < kMaxStepHalvings && !(next_residual < residual); ++h) {
        scale *= 0.5;
        next = theta - scale * step;
        next_residual = std::abs(ThetaD(next) - theta_d);
      }
      if (!(next_residual < residual)) break;  // stagnated
      theta = next;
      residual = next_residual;
      ++out.iterations;
    }
    out.theta = theta;
    out.residual = residual;
    out.converged =
        residual <= tolerance && theta >= 0.0 && theta < std::numbers::pi && Monotonic(theta);
    return out;
  }
};

void CheckFinite(std::string_view where, std::span<const double> coefficients,
                 std::span<const std::string_view> names) {
  for (size_t i = 0; i < coefficients.size(); ++i) {
    if (!std::isfinite(coefficients[i])) {
      throw InvalidArgument(fmt::format("{}: coefficient {} (index {}) must be finite, got {}",
                                        where, names[i], i, coefficients[i]));
    }
  }
}

std::string CountList(std::span<const double> coefficients) {
  return fmt::format("{}", fmt::join(coefficients, ", "));
}

}  // namespace

std::string ToString(DistortionModel model) {
  switch (model) {
    case DistortionModel::kNone:
      return "none";
    case DistortionModel::kRadialTangential:
      return "radtan";
    case DistortionModel::kFisheye:
      return "fisheye";
  }
  return "unknown";
}

Distortion Distortion::RadialTangential(std::span<const double> coefficients) {
  constexpr std::string_view kWhere = "Distortion::RadialTangential";
  const size_t n = coefficients.size();
  if (n != 4 && n != 5 && n != 8 && n != 12 && n != 14) {
    throw InvalidArgument(fmt::format(
        "{}: expected 4, 5, 8, 12 or 14 coefficients (k1 k2 p1 p2 [k3 [k4 k5 k6 [s1 s2 s3 s4 "
        "[tau_x tau_y]]]]), got {}",
        kWhere, n));
  }
  CheckFinite(kWhere, coefficients, kRadTanNames);
  for (size_t i = 8; i < n; ++i) {
    if (coefficients[i] != 0.0) {
      throw InvalidArgument(
          fmt::format("{}: coefficient {} (index {}) must be 0: thin-prism and tilt terms are not "
                      "supported, got {}",
                      kWhere, kRadTanNames[i], i, coefficients[i]));
    }
  }
  Distortion d;
  d.model_ = DistortionModel::kRadialTangential;
  d.coefficients_.assign(8, 0.0);
  std::copy_n(coefficients.begin(), std::min<size_t>(n, 8), d.coefficients_.begin());
  return d;
}

Distortion Distortion::Fisheye(std::span<const double> coefficients) {
  constexpr std::string_view kWhere = "Distortion::Fisheye";
  if (coefficients.size() != 4) {
    throw InvalidArgument(fmt::format("{}: expected exactly 4 coefficients (k1 k2 k3 k4), got {}",
                                      kWhere, coefficients.size()));
  }
  static constexpr std::array<std::string_view, 4> kNames = {"k1", "k2", "k3", "k4"};
  CheckFinite(kWhere, coefficients, kNames);
  Distortion d;
  d.model_ = DistortionModel::kFisheye;
  d.coefficients_.assign(coefficients.begin(), coefficients.end());
  return d;
}

Distortion Distortion::FromCoefficients(DistortionModel model,
                                        std::span<const double> coefficients) {
  switch (model) {
    case DistortionModel::kRadialTangential:
      return RadialTangential(coefficients);
    case DistortionModel::kFisheye:
      return Fisheye(coefficients);
    case DistortionModel::kNone:
      for (size_t i = 0; i < coefficients.size(); ++i) {
        if (coefficients[i] != 0.0) {
          throw InvalidArgument(fmt::format(
              "Distortion::FromCoefficients: model none takes no coefficients or all zeros, got "
              "{} at index {} (coefficients: {})",
              coefficients[i], i, CountList(coefficients)));
        }
      }
      return Distortion();
  }
  throw InvalidArgument(
      fmt::format("Distortion::FromCoefficients: unknown model {}", static_cast<int>(model)));
}

bool Distortion::IsIdentity() const {
  switch (model_) {
    case DistortionModel::kNone:
      return true;
    case DistortionModel::kRadialTangential:
      return std::all_of(coefficients_.begin(), coefficients_.end(),
                         [](double c) { return c == 0.0; });
    case DistortionModel::kFisheye:
      return false;  // the equidistant projection, not the pinhole
  }
  return false;
}

bool Distortion::DistortRay(const Eigen::Vector3d& ray_C, Eigen::Vector2d* xd) const {
  if (!ray_C.allFinite()) return false;
  const double X = ray_C.x(), Y = ray_C.y(), Z = ray_C.z();
  if (model_ != DistortionModel::kFisheye) {
    if (!(Z > 0.0)) return false;
    *xd = Distort({X / Z, Y / Z});
    return xd->allFinite();
  }
  const FisheyeModel f(coefficients_);
  const double rho = std::sqrt(X * X + Y * Y);
  // The angle from the optical axis, valid beyond 90 degrees (OpenCV's atan(r) is not).
  const double theta = std::atan2(rho, Z);
  if (Z > 0.0) {
    // Same steps as cv::fisheye::projectPoints, with theta from atan2.
    const Eigen::Vector2d x(X / Z, Y / Z);
    const double r = std::sqrt(x.dot(x));
    if (!(r > kFisheyeSmallRadius)) {
      *xd = x;
      return true;
    }
    *xd = x * (f.ThetaD(theta) * (1.0 / r));
    return xd->allFinite();
  }
  // At or behind the image plane: theta_d times the unit direction of (X, Y). The ray straight
  // backward (and the zero vector) has no direction in the image.
  if (!(rho > 0.0)) return false;
  *xd = Eigen::Vector2d(X, Y) * (f.ThetaD(theta) / rho);
  return xd->allFinite();
}

Eigen::Vector2d Distortion::Distort(const Eigen::Vector2d& xy) const {
  const double x = xy.x(), y = xy.y();
  switch (model_) {
    case DistortionModel::kNone:
      return xy;
    case DistortionModel::kRadialTangential: {
      // cv::projectPoints (calibration.cpp), same order of operations.
      const RadTanModel k(coefficients_);
      const double r2 = x * x + y * y, r4 = r2 * r2, r6 = r4 * r2;
      const double a1 = 2 * x * y, a2 = r2 + 2 * x * x, a3 = r2 + 2 * y * y;
      const double cdist = 1 + k.k1 * r2 + k.k2 * r4 + k.k3 * r6;
      const double icdist2 = 1. / (1 + k.k4 * r2 + k.k5 * r4 + k.k6 * r6);
      return {x * cdist * icdist2 + k.p1 * a1 + k.p2 * a2,
              y * cdist * icdist2 + k.p1 * a3 + k.p2 * a1};
    }
    case DistortionModel::kFisheye: {
      // cv::fisheye::projectPoints, for a point in front of the camera.
      const FisheyeModel f(coefficients_);
      const double r = std::sqrt(xy.dot(xy));
      if (!(r > kFisheyeSmallRadius)) return xy;
      return xy * (f.ThetaD(std::atan(r)) * (1.0 / r));
    }
  }
  return xy;
}

Eigen::Matrix2d Distortion::DistortJacobian(const Eigen::Vector2d& xy) const {
  const double x = xy.x(), y = xy.y();
  switch (model_) {
    case DistortionModel::kNone:
      return Eigen::Matrix2d::Identity();
    case DistortionModel::kRadialTangential: {
      const RadTanModel k(coefficients_);
      const double s = x * x + y * y;
      const double N = 1 + s * (k.k1 + s * (k.k2 + s * k.k3));
      const double D = 1 + s * (k.k4 + s * (k.k5 + s * k.k6));
      const double dN = k.k1 + s * (2 * k.k2 + s * 3 * k.k3);
      const double dD = k.k4 + s * (2 * k.k5 + s * 3 * k.k6);
      const double c = N / D;
      const double dc = (dN * D - N * dD) / (D * D);  // dc / ds
      Eigen::Matrix2d J;
      J(0, 0) = c + 2 * x * x * dc + 2 * k.p1 * y + 6 * k.p2 * x;
      J(0, 1) = 2 * x * y * dc + 2 * k.p1 * x + 2 * k.p2 * y;
      J(1, 0) = J(0, 1);
      J(1, 1) = c + 2 * y * y * dc + 6 * k.p1 * y + 2 * k.p2 * x;
      return J;
    }
    case DistortionModel::kFisheye: {
      const FisheyeModel f(coefficients_);
      const double r = std::sqrt(xy.dot(xy));
      if (!(r > kFisheyeSmallRadius)) return Eigen::Matrix2d::Identity();
      // xd = g(r) xy with g = theta_d(atan r) / r: J = g I + g'(r) / r * xy xy^T.
      const double theta = std::atan(r);
      const double g = f.ThetaD(theta) / r;
      const double dg = (f.ThetaDPrime(theta) / (1 + r * r) - g) / r;
      return g * Eigen::Matrix2d::Identity() + (dg / r) * xy * xy.transpose();
    }
  }
  return Eigen::Matrix2d::Identity();
}

UndistortResult Distortion::Undistort(const Eigen::Vector2d& xd, double tolerance,
                                      int max_iterations) const {
  UndistortResult result;
  result.point = xd;
  if (!xd.allFinite()) {
    result.residual = std::numeric_limits<double>::infinity();
    return result;
  }
  switch (model_) {
    case DistortionModel::kNone:
      result.converged = true;
      return result;

    case DistortionModel::kFisheye: {
      const double theta_d = std::sqrt(xd.dot(xd));
      if (!(theta_d > kFisheyeSmallRadius)) {
        // Distort is the identity there (OpenCV's small-radius rule).
        result.converged = true;
        return result;
      }
      const FisheyeModel::Inverse inverse =
          FisheyeModel(coefficients_).Solve(theta_d, tolerance, max_iterations);
      result.iterations = inverse.iterations;
      // Normalized coordinates exist only in front of the camera (theta < 90 degrees).
      const bool in_front = inverse.theta < 0.5 * std::numbers::pi;
      result.point = xd * (std::tan(inverse.theta) / theta_d);
      const Eigen::Vector2d back = Distort(result.point);
      result.residual = (back - xd).norm();
      if (!std::isfinite(result.residual))
        result.residual = std::numeric_limits<double>::infinity();
      result.converged = inverse.converged && in_front && result.residual <= tolerance;
      return result;
    }

    case DistortionModel::kRadialTangential: {
      // Newton with the analytic Jacobian from x = xd (where OpenCV's fixed-point iteration
      // starts too), each step halved while it does not reduce the residual.
      Eigen::Vector2d x = xd;
      double residual = (Distort(x) - xd).norm();
      while (residual > tolerance && result.iterations < max_iterations) {
        const Eigen::Matrix2d J = DistortJacobian(x);
        const double det = J.determinant();
        const double scale = J.cwiseAbs().maxCoeff();
        if (!std::isfinite(det) || !(std::abs(det) > kSingularJacobian * scale * scale)) break;
        const Eigen::Vector2d step = J.inverse() * (Distort(x) - xd);
        double factor = 1.0;
        Eigen::Vector2d next = x - step;
        double next_residual = (Distort(next) - xd).norm();
        for (int h = 0; h < kMaxStepHalvings && !(next_residual < residual); ++h) {
          factor *= 0.5;
          next = x - factor * step;
          next_residual = (Distort(next) - xd).norm();
        }
        if (!(next_residual < residual)) break;  // stagnated: rounding floor or no root
        x = next;
        residual = next_residual;
        ++result.iterations;
      }
      result.point = x;
      result.residual =
          std::isfinite(residual) ? residual : std::numeric_limits<double>::infinity();
      // A root counts only in the region where the model is one-to-one: the radial profile
      // increasing from the centre out to |x| and an orientation-preserving Jacobian at x.
      // Elsewhere a root exists (the model folds back) but it is not the lens's answer.
      const RadTanModel k(coefficients_);
      result.converged = residual <= tolerance && DistortJacobian(x).determinant() > 0.0 &&
                         k.RadiallyMonotonic(x.squaredNorm());
      return result;
    }
  }
  return result;
}

bool Distortion::UndistortToRay(const Eigen::Vector2d& xd, Eigen::Vector3d* ray_C,
                                double tolerance) const {
  if (!xd.allFinite()) return false;
  if (model_ != DistortionModel::kFisheye) {
    const UndistortResult result = Undistort(xd, tolerance);
    if (!result.converged) return false;
    *ray_C = Eigen::Vector3d(result.point.x(), result.point.y(), 1.0).normalized();
    return true;
  }
  const double theta_d = std::sqrt(xd.dot(xd));
  if (!(theta_d > kFisheyeSmallRadius)) {
    *ray_C = Eigen::Vector3d(xd.x(), xd.y(), 1.0).normalized();
    return true;
  }
  const FisheyeModel::Inverse inverse = FisheyeModel(coefficients_).Solve(theta_d, tolerance, 100);
  if (!inverse.converged) return false;
  const Eigen::Vector2d direction = xd / theta_d;
  const double sin_theta = std::sin(inverse.theta);
  *ray_C = Eigen::Vector3d(sin_theta * direction.x(), sin_theta * direction.y(),
                           std::cos(inverse.theta));
  return true;
}

}  // namespace saccade::geometry
