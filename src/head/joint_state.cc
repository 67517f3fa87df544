#include "saccade/head/joint_state.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>

#include "saccade/core/error.h"

namespace saccade::head {

namespace {
const JointNames& NoNames() {
  static const JointNames none;
  return none;
}
}  // namespace

JointState::JointState(std::shared_ptr<const JointNames> joint_names)
    : names_(std::move(joint_names)),
      values_(Eigen::VectorXd::Zero(names_ ? static_cast<Eigen::Index>(names_->size()) : 0)) {}

JointState::JointState(std::shared_ptr<const JointNames> joint_names, Eigen::VectorXd values)
    : names_(std::move(joint_names)), values_(std::move(values)) {
  const size_t count = names_ ? names_->size() : 0;
  if (count != static_cast<size_t>(values_.size())) {
    throw InvalidArgument(fmt::format("JointState: {} values for {} joints ({})", values_.size(),
                                      count, ListNames(names())));
  }
}

JointState JointState::Popeye(double pan, double tilt, double left, double right) {
  return JointState(PopeyeNames(), Eigen::Vector4d(pan, tilt, left, right));
}

const std::shared_ptr<const JointNames>& JointState::PopeyeNames() {
  static const std::shared_ptr<const JointNames> names =
      std::make_shared<const JointNames>(JointNames{"pan", "tilt", "left", "right"});
  return names;
}

const JointNames& JointState::names() const { return names_ ? *names_ : NoNames(); }

int JointState::Find(const std::string& name) const {
  const JointNames& all = names();
  for (size_t i = 0; i < all.size(); ++i) {
    if (all[i] == name) return static_cast<int>(i);
  }
  return -1;
}

double& JointState::at(const std::string& name) {
  const int i = Find(name);
  if (i < 0) {
    throw InvalidArgument(
        fmt::format("no joint '{}'; the joints are: {}", name, ListNames(names())));
  }
  return values_[i];
}

double JointState::at(const std::string& name) const {
  return const_cast<JointState*>(this)->at(name);
}

JointState JointState::ArrangedAs(const std::shared_ptr<const JointNames>& order) const {
  const JointNames& wanted = order ? *order : NoNames();
  std::vector<std::string> unknown;
  std::vector<std::string> missing;
  for (const std::string& n : this->names()) {
    if (std::find(wanted.begin(), wanted.end(), n) == wanted.end()) unknown.push_back(n);
  }
  Eigen::VectorXd values(wanted.size());
  for (size_t i = 0; i < wanted.size(); ++i) {
    const int j = Find(wanted[i]);
    if (j < 0) {
      missing.push_back(wanted[i]);
    } else {
      values[i] = values_[j];
    }
  }
  if (!unknown.empty() || !missing.empty()) {
    std::string what;
    if (!unknown.empty()) what += fmt::format("unknown joint(s) {}", ListNames(unknown));
    if (!missing.empty()) {
      what += fmt::format("{}missing joint(s) {}", what.empty() ? "" : "; ", ListNames(missing));
    }
    throw InvalidArgument(fmt::format("{}; the head's joints are: {}", what, ListNames(wanted)));
  }
  return JointState(order, std::move(values));
}

bool JointState::operator==(const JointState& other) const {
  return names() == other.names() && values_ == other.values_;
}

std::string ListNames(const JointNames& names) {
  return names.empty() ? std::string("(none)") : fmt::format("{}", fmt::join(names, ", "));
}

}  // namespace saccade::head
