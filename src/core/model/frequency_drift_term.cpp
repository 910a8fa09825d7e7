// Natural frequency drifting linearly during a record (beyond the paper; e.g. temperature):
// c_m(t) = c_m + cm_rate t, so F gets -omega cm_rate t (f, g). cm_rate is tilde (÷ omega) [1/s^2].
// Averaged: t times the c_m column of (2.5), 2 q' += cm_rate t (p1, -q1, p2, -q2).
#include "cvg_bench/core/model/model_terms.h"

namespace cvg_bench {
namespace {

class FrequencyDriftTerm : public ModelTerm {
 public:
  std::string name() const override { return "cm_rate"; }
  std::vector<std::string> parameterNames() const override { return {"cm_rate"}; }
  std::string description() const override {
    return "natural frequency drifting linearly in time during the record (temperature drift)";
  }
  std::vector<CandidateExtension> candidates() const override {
    return {{"cm_rate", "cm_rate", "natural-frequency drift during the record", "1/s^2",
             "phase-rate (tangential) residual growing linearly with time", false, true, false, 4}};
  }
  bool appliesTo(ExperimentMode mode) const override { return mode == ExperimentMode::kFreeDecay; }
  bool isTimeVarying() const override { return true; }
  void averagedColumns(const Eigen::Vector4d& q, const SlowContext& c,
                       Eigen::Ref<Eigen::MatrixXd> d) const override {
    d(0, 0) = c.t_s * q[1];
    d(1, 0) = -c.t_s * q[0];
    d(2, 0) = c.t_s * q[3];
    d(3, 0) = -c.t_s * q[2];
  }
  // t cm_rate (p1, -q1, p2, -q2) is linear in q.
  void averagedJacobian(const Eigen::Vector4d&, const SlowContext& c,
                        const Eigen::Ref<const Eigen::VectorXd>& z_term,
                        Eigen::Matrix4d& jacobian) const override {
    const double r = c.t_s * z_term[0];
    jacobian.setZero();
    jacobian(0, 1) = r;
    jacobian(1, 0) = -r;
    jacobian(2, 3) = r;
    jacobian(3, 2) = -r;
  }
  void fastColumns(const FastState& s, const FastContext& c,
                   Eigen::Ref<Eigen::MatrixXd> cols) const override {
    cols(0, 0) = -c.omega_rad_s * c.t_s * s.f;
    cols(1, 0) = -c.omega_rad_s * c.t_s * s.g;
  }
};

}  // namespace

ModelTermPtr makeFrequencyDriftTerm() {
  return std::make_shared<FrequencyDriftTerm>();
}

}  // namespace cvg_bench
