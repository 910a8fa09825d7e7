#include "cvg_bench/core/model/resonator_model.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "cvg_bench/core/common/errors.h"

namespace cvg_bench {

double detuningRate(double omega_rad_s, double omega0_rad_s) {
  requirePositive(omega_rad_s, "omega");
  requirePositive(omega0_rad_s, "omega0");
  return (omega0_rad_s - omega_rad_s) * (omega0_rad_s + omega_rad_s) / omega0_rad_s;
}

Eigen::Vector4d detuningDirection(const Eigen::Vector4d& q) {
  return Eigen::Vector4d(q[1], -q[0], q[3], -q[2]);
}

ExperimentMode parseExperimentMode(const std::string& name) {
  if (name == "free_decay") return ExperimentMode::kFreeDecay;
  if (name == "forced") return ExperimentMode::kForced;
  throw InputError("unknown mode '" + name + "' (known: free_decay, forced)");
}

std::string experimentModeName(ExperimentMode mode) {
  return mode == ExperimentMode::kForced ? "forced" : "free_decay";
}

ResonatorModel::ResonatorModel(const std::string& spec, ExperimentMode mode) : mode_(mode) {
  std::vector<std::string> parts;
  std::stringstream ss(spec);
  std::string item;
  while (std::getline(ss, item, '+')) {
    item.erase(0, item.find_first_not_of(" \t"));
    item.erase(item.find_last_not_of(" \t") + 1);
    if (item.empty()) throw InputError("empty term in model '" + spec + "'");
    parts.push_back(item);
  }
  if (parts.empty()) throw InputError("empty model specification");
  // getline drops a trailing empty item: "xi+" must fail like "xi++kappa".
  const auto last = spec.find_last_not_of(" \t");
  if (spec[last] == '+') throw InputError("empty term at the end of model '" + spec + "'");
  addTerms(parts, spec);
}

ResonatorModel::ResonatorModel(const std::vector<std::string>& extensions, ExperimentMode mode)
    : mode_(mode) {
  std::string spec = "linear";
  for (const auto& e : extensions) spec += "+" + e;  // for the messages only
  addTerms(extensions, spec);
}

const std::string& ResonatorModel::muName() {
  static const std::string name = "mu";
  return name;
}

ResonatorModel ResonatorModel::linearPart() const {
  std::vector<std::string> linear;
  for (const auto& e : extensions_)
    if (e != muName()) linear.push_back(e);
  return ResonatorModel(linear, mode_);
}

void ResonatorModel::addTerms(const std::vector<std::string>& parts, const std::string& spec) {
  terms_.push_back(makeModelTerm("linear"));
  if (mode_ == ExperimentMode::kForced) terms_.push_back(makeModelTerm("controls"));
  for (const auto& p : parts) {
    if (p == "linear") continue;
    if (p == "controls") {
      if (mode_ != ExperimentMode::kForced)
        throw InputError("term 'controls' exists only in forced mode");
      continue;
    }
    if (p == muName()) {
      if (mode_ != ExperimentMode::kForced)
        throw InputError("term 'mu' (control nonlinearity) exists only in forced mode");
      if (std::find(extensions_.begin(), extensions_.end(), p) != extensions_.end())
        throw InputError("term 'mu' given twice in model '" + spec + "'");
      // mu is bilinear with u~ (3.2): it is not a linear column; estimators handle it (Ceres) and
      // the model carries it as an extension name only.
      extensions_.push_back(p);
      estimates_mu_ = true;
      continue;
    }
    if (std::find(extensions_.begin(), extensions_.end(), p) != extensions_.end())
      throw InputError("term '" + p + "' given twice in model '" + spec + "'");
    auto term = makeModelTerm(p);
    if (!term->appliesTo(mode_))
      throw InputError("term '" + p + "' does not apply to " + experimentModeName(mode_) + " data");
    extensions_.push_back(p);
    terms_.push_back(term);
  }
  int offset = 0;
  for (const auto& t : terms_) {
    if (offset + t->numParameters() > kMaxModelParameters)
      throw InputError("model '" + spec + "' has too many parameters");
    offsets_.push_back(offset);
    sizes_.push_back(t->numParameters());
    for (const auto& n : t->parameterNames()) names_.push_back(n);
    offset += t->numParameters();
  }
}

std::string ResonatorModel::spec() const {
  std::string s = "linear";
  for (const auto& e : extensions_) s += "+" + e;
  return s;
}

int ResonatorModel::indexOf(const std::string& name) const {
  auto it = std::find(names_.begin(), names_.end(), name);
  return it == names_.end() ? -1 : static_cast<int>(it - names_.begin());
}

void ResonatorModel::regressor(const Eigen::Vector4d& q, const SlowContext& ctx,
                               Eigen::Ref<Eigen::MatrixXd> d) const {
  for (size_t i = 0; i < terms_.size(); ++i) {
    terms_[i]->averagedColumns(q, ctx, d.middleCols(offsets_[i], sizes_[i]));
  }
}

void ResonatorModel::regressorJacobian(const Eigen::Vector4d& q, const SlowContext& ctx,
                                       const Eigen::Ref<const Eigen::VectorXd>& z,
                                       Eigen::Matrix4d& jacobian) const {
  if (z.size() != numParameters())
    throw InputError("regressor Jacobian: " + std::to_string(z.size()) + " values for " +
                     std::to_string(numParameters()) + " parameters of model " + spec());
  // Each term writes its own matrix and the sum comes last: adding right after a term's scalar
  // stores would stall on store forwarding.
  Eigen::Matrix4d parts[kMaxModelParameters];
  const size_t m = terms_.size();
  for (size_t i = 0; i < m; ++i)
    terms_[i]->averagedJacobian(q, ctx, z.segment(offsets_[i], sizes_[i]), parts[i]);
  jacobian = parts[0];
  for (size_t i = 1; i < m; ++i) jacobian += parts[i];
}

Eigen::Matrix4d ResonatorModel::slowJacobian(const Eigen::Vector4d& q, const SlowContext& ctx,
                                             const Eigen::VectorXd& z, double detuning_rate) const {
  Eigen::Matrix4d g;
  regressorJacobian(q, ctx, z, g);
  // d(p1, -q1, p2, -q2)/dq
  Eigen::Matrix4d dir = Eigen::Matrix4d::Zero();
  dir(0, 1) = 1.0;
  dir(1, 0) = -1.0;
  dir(2, 3) = 1.0;
  dir(3, 2) = -1.0;
  return 0.5 * (g - detuning_rate * dir);
}

Eigen::MatrixXd ResonatorModel::regressor(const Eigen::Vector4d& q, const SlowContext& ctx) const {
  Eigen::MatrixXd d(4, numParameters());
  regressor(q, ctx, d);
  return d;
}

Eigen::Vector4d ResonatorModel::slowDerivative(const Eigen::Vector4d& q, const SlowContext& ctx,
                                               const Eigen::VectorXd& z,
                                               double detuning_rate) const {
  Eigen::Matrix<double, 4, Eigen::Dynamic, 0, 4, kMaxModelParameters> d(4, numParameters());
  regressor(q, ctx, d);
  return 0.5 * (d * z - detuning_rate * detuningDirection(q));
}

Eigen::Vector2d ResonatorModel::fastForce(const FastState& s, const FastContext& ctx,
                                          const Eigen::VectorXd& z) const {
  Eigen::Matrix<double, 2, Eigen::Dynamic, 0, 2, kMaxModelParameters> cols(2, numParameters());
  for (size_t i = 0; i < terms_.size(); ++i) {
    terms_[i]->fastColumns(s, ctx, cols.middleCols(offsets_[i], sizes_[i]));
  }
  return cols * z;
}

Eigen::VectorXd ResonatorModel::parameterVector(const ParameterValues& values, bool strict) const {
  Eigen::VectorXd z = Eigen::VectorXd::Zero(numParameters());
  for (const auto& kv : values) {
    requireFinite(kv.second, "parameter " + kv.first);
    const int i = indexOf(kv.first);
    if (i >= 0) {
      z[i] = kv.second;
    } else if (strict && kv.first != muName()) {
      throw InputError("parameter '" + kv.first + "' is not part of model " + spec());
    }
  }
  return z;
}

ParameterValues ResonatorModel::parameterValues(const Eigen::VectorXd& z) const {
  ParameterValues v;
  for (int i = 0; i < numParameters(); ++i) v[names_[i]] = z[i];
  return v;
}

}  // namespace cvg_bench
