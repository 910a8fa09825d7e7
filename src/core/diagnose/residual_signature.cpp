#include "cvg_bench/core/diagnose/residual_signature.h"

#include <algorithm>
#include <boost/math/distributions/normal.hpp>
#include <boost/math/distributions/students_t.hpp>
#include <cmath>
#include <sstream>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/model/orbit_elements.h"

namespace cvg_bench {

std::vector<BlockResidual> blockResiduals(const Eigen::VectorXd& residuals,
                                          const std::vector<Eigen::Vector4d>& q_blocks,
                                          const std::vector<double>& abscissa,
                                          const std::vector<double>& detuning) {
  const size_t n = q_blocks.size();
  if (static_cast<size_t>(residuals.size()) != 4 * n || abscissa.size() != n ||
      (!detuning.empty() && detuning.size() != n))
    throw InputError("blockResiduals: sizes of residuals, blocks, abscissa and detuning differ");
  std::vector<BlockResidual> out(n);
  for (size_t i = 0; i < n; ++i) {
    BlockResidual& b = out[i];
    b.abscissa = abscissa[i];
    b.detuning = detuning.empty() ? 0.0 : detuning[i];
    b.e = residuals.segment<4>(4 * i);
    b.q = q_blocks[i];
    b.amp2 = b.q.squaredNorm();
    const Eigen::Vector4d jq(-b.q[1], b.q[0], -b.q[3], b.q[2]);
    if (b.amp2 > 0.0) {
      b.radial = b.e.dot(b.q) / std::sqrt(b.amp2);
      b.tangential = b.e.dot(jq) / std::sqrt(b.amp2);
    }
    b.theta = orbitFromSlow(b.q).theta;
  }
  return out;
}

const SignatureEntry* ResidualSignature::strongest() const {
  const SignatureEntry* best = nullptr;
  for (const auto& e : entries)
    if (!best || e.p_value < best->p_value) best = &e;
  return best;
}

std::string ResidualSignature::describe(double alpha) const {
  std::vector<const SignatureEntry*> hits;
  for (const auto& e : entries)
    if (e.p_value < alpha / std::max<size_t>(1, entries.size())) hits.push_back(&e);
  if (hits.empty()) return "no significant residual structure";
  std::sort(hits.begin(), hits.end(), [](const SignatureEntry* a, const SignatureEntry* b) {
    return a->p_value < b->p_value;
  });
  std::ostringstream s;
  s.precision(2);
  for (size_t i = 0; i < hits.size() && i < 3; ++i) {
    if (i) s << "; ";
    s << (hits[i]->component == "tangential" ? "phase-rate" : "amplitude-rate")
      << " residual correlates with " << hits[i]->variable << " (r = " << hits[i]->correlation
      << ", p = " << std::scientific << hits[i]->p_value << std::defaultfloat << ")";
  }
  return s.str();
}

namespace {

double correlationPValue(double r, int n) {
  if (n < 4 || !std::isfinite(r)) return 1.0;
  const double rr = std::min(std::abs(r), 1.0 - 1e-15);
  const double t = rr * std::sqrt((n - 2) / (1.0 - rr * rr));
  const boost::math::students_t dist(n - 2);
  return std::min(1.0, 2.0 * boost::math::cdf(boost::math::complement(dist, t)));
}

SignatureEntry makeEntry(const std::string& variable, const std::string& component,
                         const std::vector<double>& x, const std::vector<double>& y, int num_bins) {
  SignatureEntry e;
  e.variable = variable;
  e.component = component;
  const int n = static_cast<int>(x.size());
  e.n_used = n;
  if (n < 4) return e;
  double mx = 0, my = 0;
  for (int i = 0; i < n; ++i) mx += x[i], my += y[i];
  mx /= n, my /= n;
  double sxx = 0, syy = 0, sxy = 0;
  for (int i = 0; i < n; ++i) {
    sxx += (x[i] - mx) * (x[i] - mx);
    syy += (y[i] - my) * (y[i] - my);
    sxy += (x[i] - mx) * (y[i] - my);
  }
  if (sxx > 0 && syy > 0) {
    e.correlation = sxy / std::sqrt(sxx * syy);
    e.p_value = correlationPValue(e.correlation, n);
  }
  // Equal-count bins along the variable.
  std::vector<int> order(n);
  for (int i = 0; i < n; ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](int a, int b) { return x[a] < x[b]; });
  const int bins = std::min(num_bins, std::max(1, n / 3));
  for (int b = 0; b < bins; ++b) {
    const int lo = b * n / bins, hi = (b + 1) * n / bins;
    SignatureBin bin;
    bin.count = hi - lo;
    if (bin.count <= 0) continue;
    double sx = 0, sy = 0, syy2 = 0;
    for (int i = lo; i < hi; ++i) sx += x[order[i]], sy += y[order[i]];
    bin.center = sx / bin.count;
    bin.mean = sy / bin.count;
    for (int i = lo; i < hi; ++i) syy2 += (y[order[i]] - bin.mean) * (y[order[i]] - bin.mean);
    bin.sem = bin.count > 1 ? std::sqrt(syy2 / (bin.count - 1) / bin.count) : 0.0;
    e.bins.push_back(bin);
  }
  return e;
}

}  // namespace

ResidualSignature residualSignature(const std::vector<BlockResidual>& blocks, ExperimentMode mode,
                                    int stride, int num_bins) {
  if (stride < 1) throw InputError("residualSignature: stride must be >= 1");
  if (num_bins < 2) throw InputError("residualSignature: num_bins must be >= 2");
  std::vector<double> a2, a4, tx, th, rad, tan;
  for (size_t i = 0; i < blocks.size(); i += stride) {
    const BlockResidual& b = blocks[i];
    if (!(b.amp2 > 0.0)) continue;
    a2.push_back(b.amp2);
    a4.push_back(b.amp2 * b.amp2);
    tx.push_back(mode == ExperimentMode::kForced ? b.detuning : b.abscissa);
    th.push_back(b.theta);
    rad.push_back(b.radial);
    tan.push_back(b.tangential);
  }
  ResidualSignature s;
  const std::string xname = mode == ExperimentMode::kForced ? "detuning" : "time";
  for (const auto& comp : {std::make_pair("tangential", &tan), std::make_pair("radial", &rad)}) {
    s.entries.push_back(makeEntry("amplitude^2", comp.first, a2, *comp.second, num_bins));
    s.entries.push_back(makeEntry("amplitude^4", comp.first, a4, *comp.second, num_bins));
    s.entries.push_back(makeEntry(xname, comp.first, tx, *comp.second, num_bins));
    s.entries.push_back(makeEntry("theta", comp.first, th, *comp.second, num_bins));
  }
  return s;
}

RunsTestResult runsTest(const std::vector<double>& values) {
  RunsTestResult r;
  std::vector<double> finite;
  for (double v : values)
    if (std::isfinite(v)) finite.push_back(v);
  if (finite.size() < 2) return r;
  std::vector<double> sorted = finite;
  std::sort(sorted.begin(), sorted.end());
  const size_t h = sorted.size() / 2;
  const double median = sorted.size() % 2 ? sorted[h] : 0.5 * (sorted[h - 1] + sorted[h]);
  int n_pos = 0, n_neg = 0, prev = 0;
  for (double v : finite) {
    if (v == median) continue;
    const int sign = v > median ? 1 : -1;
    (sign > 0 ? n_pos : n_neg)++;
    if (sign != prev) r.runs++;
    prev = sign;
  }
  r.n = n_pos + n_neg;
  if (n_pos == 0 || n_neg == 0) {
    r.p_value = r.n >= 8 ? 0.0 : 1.0;  // all on one side of the median: maximal structure
    return r;
  }
  const double n = r.n, n1 = n_pos, n2 = n_neg;
  r.expected = 2.0 * n1 * n2 / n + 1.0;
  const double var = 2.0 * n1 * n2 * (2.0 * n1 * n2 - n) / (n * n * (n - 1.0));
  if (!(var > 0.0)) return r;
  // Continuity correction toward the expectation.
  r.z = (r.runs + 0.5 - r.expected) / std::sqrt(var);
  r.p_value = boost::math::cdf(boost::math::normal(), std::min(r.z, 40.0));
  return r;
}

}  // namespace cvg_bench
