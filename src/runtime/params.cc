#include "saccade/runtime/params.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <map>

#include "saccade/core/error.h"

namespace saccade::runtime {
namespace {

bool IsParamIdentifier(const std::string& name) {
  if (name.empty() || !(std::isalpha(static_cast<unsigned char>(name[0])) || name[0] == '_')) {
    return false;
  }
  return std::all_of(name.begin(), name.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
  });
}

bool FiniteNumber(const nlohmann::json& v) {
  return v.is_number() && std::isfinite(v.get<double>());
}

// 1e-06, 1000000, -3: as fmt writes a double or an integer.
std::string Num(const nlohmann::json& v) {
  return v.is_number_integer() ? v.dump() : fmt::format("{}", v.get<double>());
}

// " in [0, 1000]", " in [0.1, inf]", " in (1, 4]", "" (unbounded).
std::string RangeText(const ParamInfo& p) {
  if (p.min.is_null() && p.max.is_null()) return "";
  return fmt::format(" in {}{}, {}{}", p.min_open ? "(" : "[",
                     p.min.is_null() ? "-inf" : Num(p.min), p.max.is_null() ? "inf" : Num(p.max),
                     p.max_open ? ")" : "]");
}

// Empty when `v` is a valid value of `p`; else what was expected.
std::string Check(const ParamInfo& p, const nlohmann::json& v) {
  const std::string expected = "expected " + [&] {
    switch (p.kind) {
      case ParamKind::kBool:
        return std::string("true or false");
      case ParamKind::kInteger:
        return "an integer" + RangeText(p);
      case ParamKind::kNumber:
        return "a number" + RangeText(p);
      case ParamKind::kString:
        return p.choices.empty() ? std::string("a string")
                                 : fmt::format("one of {}", fmt::join(p.choices, ", "));
      case ParamKind::kStrings:
        return std::string("a non-empty list of strings");
      case ParamKind::kNumbers:
        return fmt::format("{} finite numbers", p.count);
      case ParamKind::kObject:
        return std::string("a map");
    }
    return std::string();
  }();
  const auto in_range = [&](double x) {
    return (p.min.is_null() || (p.min_open ? x > p.min.get<double>() : x >= p.min.get<double>())) &&
           (p.max.is_null() || (p.max_open ? x < p.max.get<double>() : x <= p.max.get<double>()));
  };
  bool ok = false;
  switch (p.kind) {
    case ParamKind::kBool:
      ok = v.is_boolean();
      break;
    case ParamKind::kInteger:
      ok = v.is_number_integer() && !(v.is_number_unsigned() && v.get<uint64_t>() > INT64_MAX) &&
           v.get<int64_t>() >= p.representable.first &&
           v.get<int64_t>() <= p.representable.second &&
           (p.min.is_null() || v.get<int64_t>() >= p.min.get<int64_t>()) &&
           (p.max.is_null() || v.get<int64_t>() <= p.max.get<int64_t>());
      break;
    case ParamKind::kNumber:
      ok = FiniteNumber(v) && in_range(v.get<double>());
      break;
    case ParamKind::kString:
      ok = v.is_string() &&
           (p.choices.empty() ||
            std::find(p.choices.begin(), p.choices.end(), v.get<std::string>()) != p.choices.end());
      if (v.is_string() && !ok) return expected + ", got '" + v.get<std::string>() + "'";
      break;
    case ParamKind::kStrings:
      ok = v.is_array() && !v.empty() &&
           std::all_of(v.begin(), v.end(), [](const nlohmann::json& s) { return s.is_string(); });
      break;
    case ParamKind::kNumbers:
      ok = v.is_array() && v.size() == p.count && std::all_of(v.begin(), v.end(), FiniteNumber);
      break;
    case ParamKind::kObject:
      ok = v.is_object();
      break;
  }
  return ok ? "" : expected + ", got " + v.dump();
}

}  // namespace

std::string ParamInfo::TypeText() const {
  switch (kind) {
    case ParamKind::kBool:
      return "bool";
    case ParamKind::kInteger:
      return "integer" + RangeText(*this);
    case ParamKind::kNumber:
      return "number" + RangeText(*this);
    case ParamKind::kString:
      if (!choices.empty()) return fmt::format("one of {}", fmt::join(choices, ", "));
      return path ? "file" : "string";
    case ParamKind::kStrings:
      return "list of strings";
    case ParamKind::kNumbers:
      return fmt::format("list of {} numbers", count);
    case ParamKind::kObject:
      return "map";
  }
  return "";
}

std::string ParamInfo::DefaultText() const {
  if (required) return "required";
  if (default_value.is_string()) return "\"" + default_value.get<std::string>() + "\"";
  if (default_value.is_number()) return Num(default_value);
  if (default_value.is_array() && kind == ParamKind::kStrings) {
    return fmt::format("[{}]", fmt::join(default_value.get<std::vector<std::string>>(), ", "));
  }
  return default_value.dump();
}

ParamDecl& ParamDecl::Range(double min, double max) {
  if (info_->kind == ParamKind::kInteger) {
    info_->min = static_cast<int64_t>(min);
    info_->max = static_cast<int64_t>(max);
  } else {
    info_->min = min;
    info_->max = max;
  }
  return *this;
}

ParamDecl& ParamDecl::Range(const Interval& interval) {
  if (info_->kind == ParamKind::kInteger) {
    // The integers inside: (1, 4] -> [2, 4], [0.5, 3.5) -> [1, 3].
    const double low = interval.min_open ? std::floor(interval.min) + 1 : std::ceil(interval.min);
    const double high = interval.max_open ? std::ceil(interval.max) - 1 : std::floor(interval.max);
    info_->min = std::isinf(low) ? nlohmann::json() : nlohmann::json(static_cast<int64_t>(low));
    info_->max = std::isinf(high) ? nlohmann::json() : nlohmann::json(static_cast<int64_t>(high));
    info_->min_open = info_->max_open = false;
  } else {
    info_->min = std::isinf(interval.min) ? nlohmann::json() : nlohmann::json(interval.min);
    info_->max = std::isinf(interval.max) ? nlohmann::json() : nlohmann::json(interval.max);
    info_->min_open = interval.min_open && !std::isinf(interval.min);
    info_->max_open = interval.max_open && !std::isinf(interval.max);
  }
  return *this;
}

ParamDecl& ParamDecl::Min(double min) {
  info_->min = info_->kind == ParamKind::kInteger ? nlohmann::json(static_cast<int64_t>(min))
                                                  : nlohmann::json(min);
  return *this;
}

ParamDecl& ParamDecl::Max(double max) {
  info_->max = info_->kind == ParamKind::kInteger ? nlohmann::json(static_cast<int64_t>(max))
                                                  : nlohmann::json(max);
  return *this;
}

ParamDecl& ParamDecl::Choices(std::vector<std::string> choices) {
  info_->choices = std::move(choices);
  return *this;
}

ParamDecl& ParamDecl::Unit(std::string unit) {
  info_->unit = std::move(unit);
  return *this;
}

ParamDecl& ParamDecl::Required() {
  info_->required = true;
  info_->default_value = nullptr;
  return *this;
}

ParamDecl& ParamDecl::Path() {
  info_->path = true;
  return *this;
}

ParamDecl ParamTable::Add(Entry entry) {
  const std::string& name = entry.info.name;
  if (!IsParamIdentifier(name)) {
    throw InvalidArgument("parameter name '" + name + "' is not an identifier");
  }
  for (const Entry& e : entries_) {
    if (e.info.name == name) throw InvalidArgument("parameter '" + name + "' declared twice");
  }
  entries_.push_back(std::move(entry));
  return ParamDecl(entries_.back().info);
}

void ParamTable::Apply(const nlohmann::json& params) const {
  if (!params.is_null() && !params.is_object()) {
    throw InvalidArgument("params: expected a mapping of parameters, got " + params.dump());
  }
  const nlohmann::json given = params.is_null() ? nlohmann::json::object() : params;
  std::map<std::string, const Entry*> by_name;
  for (const Entry& e : entries_) by_name[e.info.name] = &e;
  for (const auto& [key, value] : given.items()) {
    (void)value;
    if (!by_name.contains(key)) {
      std::vector<std::string> known;
      for (const auto& [name, entry] : by_name) known.push_back(name);
      throw InvalidArgument(
          known.empty()
              ? fmt::format("unknown parameter '{}' (this component has none)", key)
              : fmt::format("unknown parameter '{}' (known: {})", key, fmt::join(known, ", ")));
    }
  }
  // Check all first, then set: a bad value leaves every member as it was.
  std::vector<std::pair<const Entry*, const nlohmann::json*>> values;
  for (const Entry& e : entries_) {
    const ParamInfo& p = e.info;
    const auto it = given.find(p.name);
    if (it == given.end()) {
      if (p.required) {
        std::string what =
            p.choices.empty() ? p.TypeText() : fmt::format("one of {}", fmt::join(p.choices, ", "));
        throw InvalidArgument(
            fmt::format("parameter '{}' is required: {} ({})", p.name, what, p.doc));
      }
      values.emplace_back(&e, &p.default_value);
      continue;
    }
    const std::string why = Check(p, *it);
    if (!why.empty()) throw InvalidArgument(fmt::format("parameter '{}': {}", p.name, why));
    values.emplace_back(&e, &*it);
  }
  for (const auto& [entry, value] : values) entry->set(*value);
}

std::vector<ParamInfo> ParamTable::infos() const {
  std::vector<ParamInfo> out;
  for (const Entry& e : entries_) out.push_back(e.info);
  return out;
}

}  // namespace saccade::runtime
