#pragma once
// The valid range of one number, declared once where the value is defined (a library's
// Options) and used by everything that checks it: the Options' IsValid, and the declaration of
// the component parameter that sets it (runtime::ParamDecl::Range(const Interval&)), so that a
// library and its component cannot disagree about a value.

#include <limits>
#include <string>

namespace saccade {

/// An interval of the real line; each end closed or open, and infinite where unbounded.
struct Interval {
  double min = -std::numeric_limits<double>::infinity();
  double max = std::numeric_limits<double>::infinity();
  bool min_open = false;  ///< min itself is outside: (min, ...
  bool max_open = false;  ///< max itself is outside: ..., max)

  /// [min, max]
  static constexpr Interval Closed(double min, double max) { return {min, max, false, false}; }
  /// (min, max]
  static constexpr Interval LeftOpen(double min, double max) { return {min, max, true, false}; }
  /// [min, max)
  static constexpr Interval RightOpen(double min, double max) { return {min, max, false, true}; }
  /// [min, inf)
  static constexpr Interval AtLeast(double min) {
    return {min, std::numeric_limits<double>::infinity(), false, false};
  }
  /// (min, inf)
  static constexpr Interval Above(double min) {
    return {min, std::numeric_limits<double>::infinity(), true, false};
  }

  /// Whether `x` lies in the interval; NaN and the infinities never do (an unbounded end
  /// means every finite number on that side, as a parameter's range does).
  constexpr bool Contains(double x) const {
    return x > -std::numeric_limits<double>::infinity() &&
           x < std::numeric_limits<double>::infinity() && (min_open ? x > min : x >= min) &&
           (max_open ? x < max : x <= max);
  }
  /// "[0, 4]", "(1, 4]", "[1, inf)": the interval as mathematics writes it.
  std::string Text() const;
  /// "`name` = 0.5, expected (1, 4]": what IsValid says of a value outside.
  std::string Refusal(const std::string& name, double value) const;
};

}  // namespace saccade
