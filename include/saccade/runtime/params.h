#pragma once
// Declared parameters: a component names each parameter once, in its constructor, with the
// member it sets, its range or choices, its unit and one line of documentation:
//
//   DeclareParam("kernel_size", &options_.kernel_size, "side of the square window, odd")
//       .Range(3, 255).Unit("px");
//
// The member's value at declaration is the default (so a vision Options struct keeps the one
// default). Configure reads the pipeline file's `params` through this table: unknown names,
// wrong types, values out of range and missing required ones are errors that name the
// parameter (the pipeline loader adds the file and line). `saccade demo --list-components`
// and docs/components.md are printed from the same table (component_reference.h).

#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "saccade/core/interval.h"

namespace saccade::runtime {

enum class ParamKind {
  kBool,     ///< true | false
  kInteger,  ///< an integer, in [min, max]
  kNumber,   ///< a finite number, in [min, max]
  kString,   ///< a string, one of `choices` when there are some
  kStrings,  ///< a non-empty list of strings
  kNumbers,  ///< a list of `count` finite numbers
  kObject,   ///< a map, read by the component itself (its doc says how)
};

/// One declared parameter, as readers see it.
struct ParamInfo {
  std::string name;
  ParamKind kind = ParamKind::kString;
  nlohmann::json default_value;  ///< the member's value at declaration; null when required
  bool required = false;
  nlohmann::json min, max;  ///< null when unbounded
  bool min_open = false;    ///< kNumber: min itself is outside (an Interval's open end)
  bool max_open = false;    ///< kNumber: max itself is outside
  std::vector<std::string> choices;
  std::size_t count = 0;                                            ///< kNumbers: how many
  std::pair<int64_t, int64_t> representable{INT64_MIN, INT64_MAX};  ///< kInteger: the member's
  bool path = false;  ///< a file, relative to the pipeline file's folder
  std::string unit;   ///< "px", "m", "s", ...; "" when none
  std::string doc;

  /// "integer in [3, 255]", "one of left, right", "list of 3 numbers", ...
  std::string TypeText() const;
  /// "3", "0.25", "true", "[left, right]", "\"injected fault\"", "required".
  std::string DefaultText() const;
};

/// Refines a declaration (returned by ParamTable::Declare). Ranges apply to numbers and
/// integers, choices to strings.
class ParamDecl {
 public:
  explicit ParamDecl(ParamInfo& info) : info_(&info) {}
  ParamDecl& Range(double min, double max);
  /// The range a library declares for the value (its Options' Interval, which its IsValid
  /// checks too): the component and the library then give the same verdict on every value.
  /// On an integer, an open or fractional end becomes the nearest integer inside.
  ParamDecl& Range(const Interval& interval);
  ParamDecl& Min(double min);
  ParamDecl& Max(double max);
  ParamDecl& Choices(std::vector<std::string> choices);
  ParamDecl& Unit(std::string unit);
  /// No default: the pipeline file must give it.
  ParamDecl& Required();
  /// A file path, resolved against the pipeline file's folder by the component.
  ParamDecl& Path();

 private:
  ParamInfo* info_;
};

/// A component's parameters: declarations, and the reader that applies `params` to them.
class ParamTable {
 public:
  /// Declares `name`, which sets `*member` (bool, a signed integer type, double, std::string,
  /// std::vector<std::string>, std::vector<double> or nlohmann::json). Throws
  /// InvalidArgument when the name is taken or not an identifier.
  template <typename T>
  ParamDecl Declare(const std::string& name, T* member, std::string doc) {
    Entry entry;
    entry.info.name = name;
    entry.info.doc = std::move(doc);
    entry.info.default_value = nlohmann::json(*member);
    if constexpr (std::is_same_v<T, bool>) {
      entry.info.kind = ParamKind::kBool;
    } else if constexpr (std::is_integral_v<T> && std::is_signed_v<T>) {
      entry.info.kind = ParamKind::kInteger;
      entry.info.representable = {std::numeric_limits<T>::min(), std::numeric_limits<T>::max()};
    } else if constexpr (std::is_floating_point_v<T>) {
      entry.info.kind = ParamKind::kNumber;
    } else if constexpr (std::is_same_v<T, std::string>) {
      entry.info.kind = ParamKind::kString;
    } else if constexpr (std::is_same_v<T, std::vector<std::string>>) {
      entry.info.kind = ParamKind::kStrings;
    } else if constexpr (std::is_same_v<T, std::vector<double>>) {
      entry.info.kind = ParamKind::kNumbers;
      entry.info.count = member->size();
    } else {
      static_assert(std::is_same_v<T, nlohmann::json>, "unsupported parameter type");
      entry.info.kind = ParamKind::kObject;
    }
    // Validated by Apply before the member is set.
    entry.set = [member](const nlohmann::json& value) { *member = value.get<T>(); };
    return Add(std::move(entry));
  }

  /// Checks every parameter of `params` (an object, or null for none) and sets every declared
  /// member: to the given value, or back to its default. Throws InvalidArgument naming the
  /// parameter: "unknown parameter 'x' (known: ...)", "parameter 'x': expected an integer in
  /// [0, 1000], got -2", "parameter 'x' is required: ...". Nothing is set when it throws.
  void Apply(const nlohmann::json& params) const;

  /// The declarations, in declaration order.
  std::vector<ParamInfo> infos() const;
  bool empty() const { return entries_.empty(); }

 private:
  struct Entry {
    ParamInfo info;
    std::function<void(const nlohmann::json&)> set;
  };
  ParamDecl Add(Entry entry);
  std::deque<Entry> entries_;  // stable: a ParamDecl points into it
};

}  // namespace saccade::runtime
