#include "cvg_bench/core/demod/demodulator.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/common/number_text.h"
#include "cvg_bench/core/demod/demodulator_noise.h"
#include "cvg_bench/core/estimate/internal/simd_vector4.h"

namespace cvg_bench {
namespace {

constexpr long double kTwoPiL = 6.283185307179586476925286766559005768L;

/// Kaiser length estimate (taps per stage) used only to compare stage plans.
double tapEstimate(const LowpassSpec& s) {
  return (s.attenuation_db - 7.95) /
         (2.285 * 2.0 * M_PI * (s.stopband_hz - s.passband_hz) / s.sample_rate_hz);
}

/// Single stage, or two stages M = M1 * M2 where stage 1 (rate fs -> fs/M1) only has to keep
/// out of the final band everything that would alias into [0, stopband]: its stopband edge is
/// fs/M1 - stopband. Each stage of a cascade gets attenuation + 6.02 dB so that the product of
/// the two meets the stated chain bound. The plan with the fewest multiplies per input sample wins.
std::vector<FilterStage> planStages(double fs, int m, double fp, double fst, double att) {
  FilterStage single;
  single.spec = {fs, fp, fst, att};
  single.decimation = m;
  double best_cost = tapEstimate(single.spec) / m;
  std::vector<FilterStage> best{single};
  for (int m1 = 2; m1 <= m / 2; ++m1) {
    if (m % m1 != 0) continue;
    const int m2 = m / m1;
    const double r1 = fs / m1;
    const double fst1 = std::min(r1 - fst, 0.5 * fs);
    if (!(fst1 > fp * 1.0001) || fst1 <= fp) continue;
    FilterStage s1, s2;
    s1.spec = {fs, fp, fst1, att + 6.03};
    s1.decimation = m1;
    s2.spec = {r1, fp, fst, att + 6.03};
    s2.decimation = m2;
    if (fst > 0.5 * r1) continue;
    const double cost = tapEstimate(s1.spec) / m1 + tapEstimate(s2.spec) / m;
    if (cost < best_cost) {
      best_cost = cost;
      best = {s1, s2};
    }
  }
  return best;
}

using simd::V4;

/// Writes 4 interleaved channels (2 f cos, 2 f sin, 2 g cos, 2 g sin) for n samples whose
/// reference phase is phase0 + k dphi: four rotation lanes stepped by 4 dphi.
CVG_HOT_CLONES
void mixBlock(const double* f, const double* g, size_t n, double phase0, double dphi, double* out) {
  V4 c, s;
  for (int l = 0; l < 4; ++l) {
    c[l] = 2.0 * std::cos(phase0 + l * dphi);
    s[l] = 2.0 * std::sin(phase0 + l * dphi);
  }
  const double c4 = std::cos(4.0 * dphi), s4 = std::sin(4.0 * dphi);
  size_t k = 0;
  for (; k + 4 <= n; k += 4) {
    for (int l = 0; l < 4; ++l) {
      const double fv = f[k + l], gv = g[k + l];
      double* o = out + 4 * (k + l);
      o[0] = fv * c[l];
      o[1] = fv * s[l];
      o[2] = gv * c[l];
      o[3] = gv * s[l];
    }
    const V4 cn = c * c4 - s * s4;
    s = s * c4 + c * s4;
    c = cn;
  }
  for (int l = 0; k < n; ++k, ++l) {
    double* o = out + 4 * k;
    o[0] = f[k] * c[l];
    o[1] = f[k] * s[l];
    o[2] = g[k] * c[l];
    o[3] = g[k] * s[l];
  }
}

}  // namespace

double referencePhase(double omega_rad_s, double t_s) {
  long double x =
      std::fmod(static_cast<long double>(omega_rad_s) * static_cast<long double>(t_s), kTwoPiL);
  if (x < 0) x += kTwoPiL;
  return static_cast<double>(x);
}

std::vector<std::string> DemodulatorOptions::validate() const {
  std::vector<std::string> p;
  if (!(omega_rad_s > 0.0) || !std::isfinite(omega_rad_s))
    p.push_back("omega_rad_s (reference frequency) must be finite and > 0");
  if (!(sample_rate_hz > 0.0) || !std::isfinite(sample_rate_hz))
    p.push_back("sample_rate_hz must be finite and > 0");
  if (!(output_rate_hz > 0.0) || !std::isfinite(output_rate_hz))
    p.push_back("output_rate_hz must be finite and > 0");
  if (!(attenuation_db >= 20.0 && attenuation_db <= 300.0))
    p.push_back("attenuation_db must be in [20, 300]");
  if (!(interval_tolerance > 0.0 && interval_tolerance < 0.5))
    p.push_back("interval_tolerance must be in (0, 0.5)");
  if (!(gap_periods >= 2.0) || !std::isfinite(gap_periods)) p.push_back("gap_periods must be >= 2");
  if (anchor_interval < 4 || anchor_interval > 4096) p.push_back("anchor_interval must be 4..4096");
  if (!(passband_hz >= 0.0) || !(stopband_hz >= 0.0))
    p.push_back("passband_hz and stopband_hz must be >= 0 (0 = default)");
  if (p.empty()) {
    const double f0 = omega_rad_s / (2.0 * M_PI);
    if (f0 >= 0.5 * sample_rate_hz)
      p.push_back("reference frequency " + numberText(f0, 15) + " Hz is not below Nyquist (" +
                  numberText(0.5 * sample_rate_hz, 15) + " Hz)");
    const double m = std::round(sample_rate_hz / output_rate_hz);
    if (m < 1.0) p.push_back("output_rate_hz must be <= sample_rate_hz");
    const double out = sample_rate_hz / std::max(1.0, m);
    const double fp = passband_hz > 0.0 ? passband_hz : 0.2 * out;
    const double fst = stopband_hz > 0.0 ? stopband_hz : 0.5 * out;
    if (!(fst > fp)) p.push_back("stopband_hz must be > passband_hz");
    if (fst > 0.5 * out * (1.0 + 1e-12))
      p.push_back("stopband_hz must be <= output rate / 2 (" + numberText(0.5 * out, 15) + " Hz)");
    if (2.0 * f0 - fst <= fst)
      p.push_back("the mixing image at 2W (" + numberText(2.0 * f0, 15) +
                  " Hz) is not well inside the stopband: lower the output rate");
  }
  return p;
}

Demodulator::Demodulator(const DemodulatorOptions& options) : options_(options) {
  throwIfInvalid("demodulator options", options.validate());
  const int m = static_cast<int>(std::round(options.sample_rate_hz / options.output_rate_hz));
  const double out = options.sample_rate_hz / m;
  passband_hz_ = options.passband_hz > 0.0 ? options.passband_hz : 0.2 * out;
  stopband_hz_ = options.stopband_hz > 0.0 ? options.stopband_hz : 0.5 * out;
  stages_ =
      planStages(options.sample_rate_hz, m, passband_hz_, stopband_hz_, options.attenuation_db);
  for (FilterStage& s : stages_) {
    filters_.push_back(
        std::make_unique<PolyphaseDecimator4>(designKaiserLowpass(s.spec), s.decimation));
    s.n_taps = filters_.back()->numTaps();
  }
  SampleValidatorOptions vo;
  vo.sample_rate_hz = options.sample_rate_hz;
  vo.interval_tolerance = options.interval_tolerance;
  vo.gap_periods = options.gap_periods;
  validator_ = std::make_unique<SampleValidator>(vo);
}

Demodulator::~Demodulator() = default;
Demodulator::Demodulator(Demodulator&&) noexcept = default;
Demodulator& Demodulator::operator=(Demodulator&&) noexcept = default;

double Demodulator::outputRateHz() const {
  int m = 1;
  for (const FilterStage& s : stages_) m *= s.decimation;
  return options_.sample_rate_hz / m;
}

double Demodulator::groupDelayS() const {
  double d = 0.0;
  for (const FilterStage& s : stages_) d += 0.5 * double(s.n_taps - 1) / s.spec.sample_rate_hz;
  return d;
}

double Demodulator::latencyS() const {
  return 2.0 * groupDelayS();
}

const SampleCounters& Demodulator::counters() const {
  return validator_->counters();
}
void Demodulator::resetCounters() {
  validator_->resetCounters();
}

void Demodulator::reset() {
  validator_->reset();
  restart("reset requested");
}

void Demodulator::restart(const std::string& why) {
  for (auto& f : filters_) f->reset();
  have_envelope_ = false;
  ++segment_;
  ++validator_->counters().restarts;
  last_event_ = why;
}

void Demodulator::mixAndFilter(const double* t, const double* f, const double* g, size_t n,
                               std::vector<SlowSample>& out) {
  PolyphaseDecimator4& first = *filters_.front();
  const size_t block = std::min<size_t>(options_.anchor_interval, first.maxChunk());
  const double w = options_.omega_rad_s;
  for (size_t b = 0; b < n; b += block) {
    const size_t k = std::min(block, n - b);
    const PolyphaseDecimator4::InputSlot slot = first.prepareInput(k);
    const double phase0 = referencePhase(w, t[b]);
    const double dphi = k > 1 ? w * (t[b + k - 1] - t[b]) / double(k - 1) : 0.0;
    mixBlock(f + b, g + b, k, phase0, dphi, slot.values);
    std::copy(t + b, t + b + k, slot.times);
    auto* vals = &stage_values_[0];
    auto* times = &stage_times_[0];
    vals->clear();
    times->clear();
    first.commit(k, *vals, *times);
    if (filters_.size() > 1 && !times->empty()) {
      stage_values_[1].clear();
      stage_times_[1].clear();
      filters_[1]->push(vals->data(), times->data(), times->size(), stage_values_[1],
                        stage_times_[1]);
      vals = &stage_values_[1];
      times = &stage_times_[1];
    }
    for (size_t i = 0; i < times->size(); ++i) {
      SlowSample s;
      s.t_s = (*times)[i];
      s.q = Eigen::Map<const Eigen::Vector4d>(vals->data() + 4 * i);
      s.segment = segment_;
      out.push_back(s);
    }
    if (!times->empty()) {
      have_envelope_ = true;
      last_q_ = out.back().q;
    }
  }
}

bool Demodulator::fillMissing(const AcceptedRun& run, double t_next, std::vector<SlowSample>& out) {
  if (!have_envelope_) return false;
  // Envelope held at its latest value, evaluated at each missing timestamp's own phase (2.4).
  const int m = run.missing;
  std::vector<double> t(m), f(m), g(m);
  const double step = (t_next - run.previous_t) / (m + 1);
  for (int k = 0; k < m; ++k) {
    t[k] = run.previous_t + (k + 1) * step;
    const double ph = referencePhase(options_.omega_rad_s, t[k]);
    const double c = std::cos(ph), s = std::sin(ph);
    f[k] = last_q_[1] * s + last_q_[0] * c;
    g[k] = last_q_[3] * s + last_q_[2] * c;
  }
  validator_->counters().missing_filled += m;
  mixAndFilter(t.data(), f.data(), g.data(), m, out);
  return true;
}

void Demodulator::push(const double* t, const double* f, const double* g, size_t n,
                       std::vector<SlowSample>& out) {
  const std::vector<AcceptedRun> runs = validator_->screen(t, f, g, n);
  for (const AcceptedRun& run : runs) {
    switch (run.start) {
      case RunStart::kContinue:
      case RunStart::kRestartFirst:
        break;
      case RunStart::kFillMissing:
        if (!fillMissing(run, t[run.begin], out))
          restart(std::to_string(run.missing) +
                  " samples missing before t = " + numberText(t[run.begin], 15) +
                  " s and no envelope yet to fill them: filter restarted");
        break;
      case RunStart::kRestartGap:
        restart("gap before t = " + numberText(t[run.begin], 15) + " s: filter restarted");
        break;
      case RunStart::kRestartBad:
        restart("out-of-range sample dropped before t = " + numberText(t[run.begin], 15) +
                " s: filter state cleared");
        break;
      case RunStart::kResetBackward:
        restart("time jumped back to t = " + numberText(t[run.begin], 15) +
                " s: demodulator reset");
        break;
    }
    mixAndFilter(t + run.begin, f + run.begin, g + run.begin, run.end - run.begin, out);
  }
}

void Demodulator::push(const std::vector<double>& t, const std::vector<double>& f,
                       const std::vector<double>& g, std::vector<SlowSample>& out) {
  if (t.size() != f.size() || t.size() != g.size())
    throw InputError("Demodulator::push: t, f, g sizes differ");
  push(t.data(), f.data(), g.data(), t.size(), out);
}

SamplingSummary summarizeSampling(const std::vector<double>& t, double tolerance,
                                  double gap_periods) {
  SamplingSummary s;
  s.n = t.size();
  if (t.size() < 3) return s;
  std::vector<double> d(t.size() - 1);
  for (size_t i = 1; i < t.size(); ++i) d[i - 1] = t[i] - t[i - 1];
  std::vector<double> sorted = d;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const double med = sorted[sorted.size() / 2];
  s.median_interval_s = med;
  if (!(med > 0.0)) return s;
  size_t on = 0, mult = 0, other = 0;
  for (double x : d) {
    const double m = std::round(x / med);
    if (std::abs(x - med) <= tolerance * med)
      ++on;
    else if (m >= 2.0 && m <= gap_periods && std::abs(x - m * med) <= tolerance * med)
      ++mult;
    else
      ++other;
  }
  s.fraction_on_grid = double(on) / d.size();
  s.fraction_multiple = double(mult) / d.size();
  s.uniform = other == 0 && s.fraction_on_grid >= 0.9;
  return s;
}

SlowRecord demodulateUniform(const RawRecord& raw, DemodulatorOptions options,
                             SampleCounters* counters) {
  if (raw.t_s.size() != raw.f.size() || raw.t_s.size() != raw.g.size())
    throw InputError("raw record: t, f, g sizes differ");
  if (options.omega_rad_s <= 0.0) options.omega_rad_s = raw.omega_rad_s;
  if (options.sample_rate_hz <= 0.0) {
    const SamplingSummary s = summarizeSampling(raw.t_s, options.interval_tolerance);
    if (!(s.median_interval_s > 0.0))
      throw InputError("raw record " + raw.source + ": cannot determine the sample rate");
    options.sample_rate_hz = 1.0 / s.median_interval_s;
  }
  Demodulator demod(options);
  std::vector<SlowSample> slow;
  demod.push(raw.t_s, raw.f, raw.g, slow);
  if (counters) *counters = demod.counters();
  if (slow.empty()) {
    std::ostringstream m;
    m << "raw record " << raw.source << ": too short for the demodulator filter (needs "
      << demod.latencyS() << " s of contiguous data, has " << raw.size() << " samples)";
    throw InputError(m.str());
  }
  SlowRecord rec;
  rec.omega_rad_s = options.omega_rad_s;
  rec.source = raw.source;
  rec.metadata["mode"] = "free_decay";
  std::ostringstream d;
  d.precision(12);
  d << "uniform FIR, reference " << options.omega_rad_s << " rad/s, input "
    << options.sample_rate_hz << " Hz, output " << demod.outputRateHz() << " Hz, passband "
    << demod.passbandHz() << " Hz, stopband " << demod.stopbandHz() << " Hz at "
    << options.attenuation_db << " dB, stages";
  for (const FilterStage& s : demod.stages()) d << " " << s.n_taps << " taps/" << s.decimation;
  rec.metadata["demodulation"] = d.str();
  std::ostringstream rho;
  rho.precision(6);
  for (double r : outputNoiseCorrelation(demod.stages())) rho << (rho.tellp() > 0 ? " " : "") << r;
  if (rho.tellp() > 0) rec.metadata[kNoiseCorrelationKey] = rho.str();
  std::vector<double> segment;
  for (const SlowSample& s : slow) {
    rec.t_s.push_back(s.t_s);
    rec.q.push_back(s.q);
    segment.push_back(s.segment);
  }
  if (demod.segment() > 0) rec.extra["segment"] = segment;
  return rec;
}

}  // namespace cvg_bench
