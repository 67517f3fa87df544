#include "saccade/core/interval.h"

#include <fmt/format.h>

#include <cmath>

namespace saccade {

std::string Interval::Text() const {
  const auto end = [](double v) {
    return std::isinf(v) ? std::string(v < 0 ? "-inf" : "inf") : fmt::format("{}", v);
  };
  return fmt::format("{}{}, {}{}", min_open || std::isinf(min) ? "(" : "[", end(min), end(max),
                     max_open || std::isinf(max) ? ")" : "]");
}

std::string Interval::Refusal(const std::string& name, double value) const {
  return fmt::format("{} {}, expected {}", name, value, Text());
}

}  // namespace saccade
