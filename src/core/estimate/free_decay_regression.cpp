#include "cvg_bench/core/estimate/free_decay_regression.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/estimate/internal/regression_block_ops.h"

namespace cvg_bench {
namespace {

std::string where(const SlowRecord& r, size_t i) {
  return (r.source.empty() ? std::string("free-decay record") : r.source) + ": sample " +
         std::to_string(i);
}

}  // namespace

void validateFreeDecayRecord(const SlowRecord& record) {
  const std::string src = record.source.empty() ? "free-decay record" : record.source;
  if (record.q.size() != record.t_s.size())
    throw InputError(src + ": " + std::to_string(record.t_s.size()) + " times but " +
                     std::to_string(record.q.size()) + " samples of q");
  if (record.size() < 3)
    throw InputError(src + ": free decay needs at least 3 samples (one block of (2.7)), got " +
                     std::to_string(record.size()));
  bool varies = false;
  for (size_t i = 0; i < record.size(); ++i) {
    if (!std::isfinite(record.t_s[i])) throw InputError(where(record, i) + ": time is not finite");
    if (!record.q[i].allFinite()) throw InputError(where(record, i) + ": q is not finite");
    if (i > 0 && !(record.t_s[i] > record.t_s[i - 1]))
      throw InputError(where(record, i) + ": time " + std::to_string(record.t_s[i]) +
                       " does not increase (previous " + std::to_string(record.t_s[i - 1]) + ")");
    if (i > 0 && record.q[i] != record.q[0]) varies = true;
  }
  if (!varies)
    throw InputError(src + ": q is constant over the record: a free decay carries no information");
}

bool hasUniformTimes(const SlowRecord& record, double relative_tolerance) {
  const size_t n = record.size();
  if (n < 3) return true;
  const double mean = (record.t_s[n - 1] - record.t_s[0]) / static_cast<double>(n - 1);
  for (size_t i = 1; i < n; ++i) {
    if (std::fabs(record.t_s[i] - record.t_s[i - 1] - mean) > relative_tolerance * mean)
      return false;
  }
  return true;
}

std::vector<size_t> timeGapsOf(const SlowRecord& record) {
  const size_t n = record.size();
  std::vector<size_t> gaps;
  if (n < 8) return gaps;
  std::vector<double> dt(n - 1);
  for (size_t i = 0; i + 1 < n; ++i) dt[i] = record.t_s[i + 1] - record.t_s[i];
  std::vector<double> sorted = dt;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const double limit = 5.0 * sorted[sorted.size() / 2];
  for (size_t i = 0; i + 1 < n; ++i)
    if (dt[i] > limit) gaps.push_back(i);
  return gaps;
}

void forEachFreeDecayBlock(const ResonatorModel& model, const SlowRecord& record,
                           double uniform_time_tolerance, const RegressionVisitor& visit) {
  validateFreeDecayRecord(record);
  forEachValidatedFreeDecayBlock(model, record, hasUniformTimes(record, uniform_time_tolerance),
                                 visit);
}

void forEachValidatedFreeDecayBlock(const ResonatorModel& model, const SlowRecord& record,
                                    bool simpson, const RegressionVisitor& visit) {
  const int k = model.numParameters();
  const double t0 = record.t_s[0];
  // Rolling window of D(q) at samples i-1, i, i+1.
  RegressionBlockMatrix dm[3] = {RegressionBlockMatrix(4, k), RegressionBlockMatrix(4, k),
                                 RegressionBlockMatrix(4, k)};
  SlowContext ctx;
  ctx.t_s = 0.0;
  model.regressor(record.q[0], ctx, dm[0]);
  ctx.t_s = record.t_s[1] - t0;
  model.regressor(record.q[1], ctx, dm[1]);
  RegressionBlockMatrix dbar(4, k);
  RegressionBlock b;
  b.d = &dbar;
  const size_t n = record.size();
  // gap_after[i]: the step from sample i to i+1 is a gap.
  std::vector<char> gap_after(n, 0);
  for (size_t g : timeGapsOf(record)) gap_after[g] = 1;
  for (size_t i = 1; i + 1 < n; ++i) {
    RegressionBlockMatrix& prev = dm[(i - 1) % 3];
    RegressionBlockMatrix& mid = dm[i % 3];
    RegressionBlockMatrix& next = dm[(i + 1) % 3];
    ctx.t_s = record.t_s[i + 1] - t0;
    model.regressor(record.q[i + 1], ctx, next);
    if (gap_after[i - 1] || gap_after[i]) continue;  // spans a gap
    if (simpson) {
      const double h = 0.5 * (record.t_s[i + 1] - record.t_s[i - 1]);
      b.weights[0] = b.weights[2] = h / 3.0;
      b.weights[1] = 4.0 * h / 3.0;
    } else {
      const double h0 = record.t_s[i] - record.t_s[i - 1], h1 = record.t_s[i + 1] - record.t_s[i];
      b.weights[0] = 0.5 * h0;
      b.weights[1] = 0.5 * (h0 + h1);
      b.weights[2] = 0.5 * h1;
    }
    weightedBlockSum(b.weights[0], prev, b.weights[1], mid, b.weights[2], next, dbar);
    b.y = 2.0 * (record.q[i + 1] - record.q[i - 1]);
    b.q = record.q[i];
    b.abscissa = record.t_s[i] - t0;
    b.index = static_cast<long>(i) - 1;
    b.q_prev = record.q[i - 1];
    b.q_next = record.q[i + 1];
    b.t_prev = record.t_s[i - 1] - t0;
    b.t_next = record.t_s[i + 1] - t0;
    b.last_in_record = i + 2 == n || (i + 2 < n && gap_after[i + 1]);
    visit(b);
  }
}

}  // namespace cvg_bench
