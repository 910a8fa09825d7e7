// The blocks of the free-decay regression (2.7)-(2.8), generated one at a time (never stored):
//   y_i = 2 (q(t_{i+1}) - q(t_{i-1})),  D-bar_i = integral over [t_{i-1}, t_{i+1}] of D(q(t)) dt,
// i = 1..N-1 for samples 0..N (docs/paper.md item 8, 12). The integral is Simpson's rule
// (h/3)(D_{i-1} + 4 D_i + D_{i+1}) on uniform times and the trapezoid rule on irregular ones.
// D(q) = ResonatorModel::regressor with SlowContext.t_s = time since the record's first sample.
#pragma once

#include <functional>

#include "cvg_bench/core/estimate/least_squares_solver.h"
#include "cvg_bench/core/io/records.h"
#include "cvg_bench/core/model/resonator_model.h"

namespace cvg_bench {

/// One 4-equation block of (2.8) or (3.5) as handed to a visitor.
struct RegressionBlock {
  const RegressionBlockMatrix* d = nullptr;  ///< D-bar_i (free decay) or D_j (forced), 4 x k
  Eigen::Vector4d y;                         ///< y_i
  Eigen::Vector4d q;                         ///< the centre sample q_i / the sweep point q_j
  double abscissa = 0.0;  ///< centre time t_i - t_0 [s] (free decay) or omega0_j [rad/s] (forced)
  long index = 0;         ///< block index within its record (free decay: i - 1; forced: j)
  /// Free decay only: the neighbouring samples q_{i-1}, q_{i+1}, their times since the record's
  /// first sample, and the quadrature weights of D(q_{i-1}), D(q_i), D(q_{i+1}) in D-bar_i.
  Eigen::Vector4d q_prev = Eigen::Vector4d::Zero(), q_next = Eigen::Vector4d::Zero();
  double t_prev = 0.0, t_next = 0.0;
  double weights[3] = {0.0, 0.0, 0.0};
  bool last_in_record = false;  ///< free decay: this is block N-1 of its record
};

using RegressionVisitor = std::function<void(const RegressionBlock&)>;

/// Checks a free-decay record: >= 3 samples, sizes agree, finite values, strictly increasing times,
/// not all q equal (constant data). InputError naming the record's source and the sample.
void validateFreeDecayRecord(const SlowRecord& record);

/// Whether the record's time steps are uniform within relative_tolerance (Simpson) or not.
bool hasUniformTimes(const SlowRecord& record, double relative_tolerance);

/// The samples after which the record has a gap in time: steps over 5 x the median step (rows
/// missing, a clock jump; issue #27). An equation (2.7) differences samples i-1 and i+1 and
/// integrates D(q) between them: one that spans a gap is left out (not integrated across it).
std::vector<size_t> timeGapsOf(const SlowRecord& record);

/// Calls visit for each block i = 1..N-1 of the record (validated first), except the blocks that
/// span a gap (timeGapsOf); the block before a gap is marked last_in_record (no lag across it).
void forEachFreeDecayBlock(const ResonatorModel& model, const SlowRecord& record,
                           double uniform_time_tolerance, const RegressionVisitor& visit);
/// The same for a record already checked by validateFreeDecayRecord, with the quadrature chosen
/// (simpson = hasUniformTimes(record, tolerance)): for repeated passes over long records.
/// D(q) is evaluated once per sample (rolling window of 3).
void forEachValidatedFreeDecayBlock(const ResonatorModel& model, const SlowRecord& record,
                                    bool simpson, const RegressionVisitor& visit);

}  // namespace cvg_bench
