#include "components/internal_params.h"

#include <fmt/format.h>

#include <cmath>

#include "saccade/core/error.h"

namespace saccade::components::internal {

Params::Params(const nlohmann::json& params)
    : params_(params.is_null() ? nlohmann::json::object() : params) {
  if (!params_.is_object()) {
    throw InvalidArgument("params: expected a mapping of parameters, got " + params_.dump());
  }
}

bool Params::Has(const std::string& key) const { return params_.contains(key); }

const nlohmann::json* Params::Find(const std::string& key) {
  known_.insert(key);
  const auto it = params_.find(key);
  return it == params_.end() ? nullptr : &*it;
}

double Params::Number(const std::string& key, double fallback, double min, double max) {
  const nlohmann::json* value = Find(key);
  if (value == nullptr) return fallback;
  if (!value->is_number() || !std::isfinite(value->get<double>()) || value->get<double>() < min ||
      value->get<double>() > max) {
    throw InvalidArgument(fmt::format("parameter '{}': expected a number in [{}, {}], got {}", key,
                                      min, max, value->dump()));
  }
  return value->get<double>();
}

int64_t Params::Integer(const std::string& key, int64_t fallback, int64_t min, int64_t max) {
  const nlohmann::json* value = Find(key);
  if (value == nullptr) return fallback;
  if (!value->is_number_integer() || value->get<int64_t>() < min || value->get<int64_t>() > max) {
    throw InvalidArgument(fmt::format("parameter '{}': expected an integer in [{}, {}], got {}",
                                      key, min, max, value->dump()));
  }
  return value->get<int64_t>();
}

bool Params::Bool(const std::string& key, bool fallback) {
  const nlohmann::json* value = Find(key);
  if (value == nullptr) return fallback;
  if (!value->is_boolean()) {
    throw InvalidArgument(
        fmt::format("parameter '{}': expected true or false, got {}", key, value->dump()));
  }
  return value->get<bool>();
}

std::string Params::String(const std::string& key, const std::string& fallback) {
  const nlohmann::json* value = Find(key);
  if (value == nullptr) return fallback;
  if (!value->is_string()) {
    throw InvalidArgument(
        fmt::format("parameter '{}': expected a string, got {}", key, value->dump()));
  }
  return value->get<std::string>();
}

std::string Params::RequiredString(const std::string& key) {
  if (!Has(key)) {
    known_.insert(key);
    throw InvalidArgument(fmt::format("parameter '{}' is required", key));
  }
  return String(key, "");
}

std::string Params::Choice(const std::string& key, const std::string& fallback,
                           const std::vector<std::string>& choices) {
  const std::string value = String(key, fallback);
  for (const std::string& choice : choices) {
    if (value == choice) return value;
  }
  throw InvalidArgument(fmt::format("parameter '{}': expected one of {}, got '{}'", key,
                                    fmt::join(choices, ", "), value));
}

std::vector<std::string> Params::Strings(const std::string& key,
                                         std::vector<std::string> fallback) {
  const nlohmann::json* value = Find(key);
  if (value == nullptr) return fallback;
  std::vector<std::string> out;
  if (value->is_array()) {
    for (const nlohmann::json& item : *value) {
      if (!item.is_string()) break;
      out.push_back(item.get<std::string>());
    }
  }
  if (!value->is_array() || out.size() != value->size() || out.empty()) {
    throw InvalidArgument(fmt::format(
        "parameter '{}': expected a non-empty list of strings, got {}", key, value->dump()));
  }
  return out;
}

std::vector<double> Params::Numbers(const std::string& key, std::size_t n) {
  const nlohmann::json* value = Find(key);
  std::vector<double> out;
  if (value != nullptr && value->is_array() && value->size() == n) {
    for (const nlohmann::json& item : *value) {
      if (item.is_number() && std::isfinite(item.get<double>())) out.push_back(item.get<double>());
    }
  }
  if (out.size() != n) {
    throw InvalidArgument(fmt::format("parameter '{}': expected {} finite numbers, got {}", key, n,
                                      value == nullptr ? "nothing" : value->dump()));
  }
  return out;
}

void Params::Finish() const {
  for (const auto& [key, value] : params_.items()) {
    if (!known_.contains(key)) {
      throw InvalidArgument(
          fmt::format("unknown parameter '{}' (known: {})", key, fmt::join(known_, ", ")));
    }
  }
}

}  // namespace saccade::components::internal
