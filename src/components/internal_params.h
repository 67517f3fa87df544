#pragma once
// Reading a component's `params` (pipeline.h) with errors that name the parameter, the value
// got and the value expected; the pipeline loader adds the file and line.
#include <cstdint>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

namespace saccade::components::internal {

class Params {
 public:
  /// `params` must be an object (or null: no parameters). Throws InvalidArgument.
  explicit Params(const nlohmann::json& params);

  bool Has(const std::string& key) const;
  /// A number in [min, max]; `fallback` when absent.
  double Number(const std::string& key, double fallback, double min, double max);
  /// An integer in [min, max]; `fallback` when absent.
  int64_t Integer(const std::string& key, int64_t fallback, int64_t min, int64_t max);
  bool Bool(const std::string& key, bool fallback);
  std::string String(const std::string& key, const std::string& fallback);
  /// A required string.
  std::string RequiredString(const std::string& key);
  /// One of `choices`; `fallback` when absent.
  std::string Choice(const std::string& key, const std::string& fallback,
                     const std::vector<std::string>& choices);
  /// A list of strings; `fallback` when absent.
  std::vector<std::string> Strings(const std::string& key, std::vector<std::string> fallback);
  /// Three numbers (a point), required.
  std::vector<double> Numbers(const std::string& key, std::size_t n);

  /// Throws InvalidArgument for any key not asked for: "unknown parameter 'x' (known: ...)".
  void Finish() const;

 private:
  const nlohmann::json* Find(const std::string& key);
  nlohmann::json params_;
  std::set<std::string> known_;
};

}  // namespace saccade::components::internal
