#include "cvg_bench/core/demod/fir_lowpass.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <sstream>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/estimate/internal/simd_vector4.h"

namespace cvg_bench {
namespace {

/// Modified Bessel function of the first kind, order 0 (power series; x <= ~60 here).
double besselI0(double x) {
  const double q = 0.25 * x * x;
  double term = 1.0, sum = 1.0;
  for (int k = 1; k < 500; ++k) {
    term *= q / (double(k) * double(k));
    sum += term;
    if (term < 1e-17 * sum) break;
  }
  return sum;
}

/// Kaiser's length estimate N = (A - 7.95) / (2.285 dw) + 1, made odd.
size_t kaiserLength(const LowpassSpec& s) {
  const double dw = 2.0 * M_PI * (s.stopband_hz - s.passband_hz) / s.sample_rate_hz;
  size_t n = static_cast<size_t>(std::ceil((s.attenuation_db - 7.95) / (2.285 * dw))) + 1;
  n = std::max<size_t>(n, 3);
  return n | 1u;
}

std::vector<double> kaiserSinc(const LowpassSpec& s, size_t n) {
  const double fc = 0.5 * (s.passband_hz + s.stopband_hz) / s.sample_rate_hz;  // cycles/sample
  const double beta = kaiserBeta(s.attenuation_db);
  const double c = 0.5 * double(n - 1);
  const double i0_beta = besselI0(beta);
  std::vector<double> h(n);
  double sum = 0.0;
  for (size_t k = 0; k < n; ++k) {
    const double m = double(k) - c;
    const double sinc = m == 0.0 ? 2.0 * fc : std::sin(2.0 * M_PI * fc * m) / (M_PI * m);
    const double r = m / c;
    const double w = besselI0(beta * std::sqrt(std::max(0.0, 1.0 - r * r))) / i0_beta;
    h[k] = sinc * w;
    sum += h[k];
  }
  for (double& v : h) v /= sum;
  // Exact symmetry (the sums above are symmetric up to rounding).
  for (size_t k = 0; k < n / 2; ++k) h[n - 1 - k] = h[k];
  return h;
}

using simd::load4;
using simd::V4;

/// One output of the symmetric filter on 4 interleaved channels: x points at the window start.
/// Two accumulator chains keep the adder pipeline busy.
CVG_HOT_CLONES
void symmetricDot4(const double* half_taps, size_t half, double centre_tap, const double* x,
                   size_t n_taps, double* out) {
  V4 acc0 = centre_tap * load4(x + 4 * half);
  V4 acc1 = {0.0, 0.0, 0.0, 0.0};
  const double* hi = x + 4 * (n_taps - 1);
  size_t j = 0;
  for (; j + 1 < half; j += 2) {
    acc0 += half_taps[j] * (load4(x + 4 * j) + load4(hi - 4 * j));
    acc1 += half_taps[j + 1] * (load4(x + 4 * (j + 1)) + load4(hi - 4 * (j + 1)));
  }
  if (j < half) acc0 += half_taps[j] * (load4(x + 4 * j) + load4(hi - 4 * j));
  const V4 acc = acc0 + acc1;
  std::memcpy(out, &acc, sizeof(acc));
}

}  // namespace

std::vector<std::string> LowpassSpec::validate() const {
  std::vector<std::string> p;
  if (!(sample_rate_hz > 0.0) || !std::isfinite(sample_rate_hz))
    p.push_back("sample_rate_hz must be finite and > 0");
  if (!(passband_hz >= 0.0) || !std::isfinite(passband_hz))
    p.push_back("passband_hz must be finite and >= 0");
  if (!(stopband_hz > passband_hz) || !std::isfinite(stopband_hz))
    p.push_back("stopband_hz must be finite and > passband_hz");
  if (sample_rate_hz > 0.0 && stopband_hz > 0.5 * sample_rate_hz * (1.0 + 1e-12))
    p.push_back("stopband_hz must be <= sample_rate_hz / 2");
  if (!(attenuation_db >= 20.0 && attenuation_db <= 300.0))
    p.push_back("attenuation_db must be in [20, 300]");
  if (max_taps < 3) p.push_back("max_taps must be >= 3");
  return p;
}

double kaiserBeta(double a) {
  if (a > 50.0) return 0.1102 * (a - 8.7);
  if (a >= 21.0) return 0.5842 * std::pow(a - 21.0, 0.4) + 0.07886 * (a - 21.0);
  return 0.0;
}

double lowpassResponse(const std::vector<double>& taps, double f_hz, double sample_rate_hz) {
  // Symmetric taps: H = h_c + 2 sum_{m>=1} h_{c+m} cos(m theta); cos(m theta) by a rotation.
  const size_t n = taps.size(), c = n / 2;
  const double theta = 2.0 * M_PI * f_hz / sample_rate_hz;
  const double cs = std::cos(theta), sn = std::sin(theta);
  double re = 1.0, im = 0.0, h = taps[c];
  for (size_t m = 1; m <= c; ++m) {
    if (m % 64 == 0) {
      re = std::cos(double(m) * theta);
      im = std::sin(double(m) * theta);
    } else {
      const double r2 = re * cs - im * sn;
      im = im * cs + re * sn;
      re = r2;
    }
    h += 2.0 * taps[c + m] * re;
  }
  return h;
}

LowpassCheck checkLowpass(const std::vector<double>& taps, const LowpassSpec& s) {
  LowpassCheck out;
  const double lobe = s.sample_rate_hz / double(taps.size());
  const double nyq = 0.5 * s.sample_rate_hz;
  auto scan = [&](double a, double b, double step, bool pass) {
    if (b < a) return;
    const int n = static_cast<int>(std::ceil((b - a) / step));
    for (int i = 0; i <= n; ++i) {
      const double f = std::min(b, a + i * step);
      const double h = lowpassResponse(taps, f, s.sample_rate_hz);
      if (pass)
        out.passband_deviation = std::max(out.passband_deviation, std::abs(h - 1.0));
      else
        out.stopband_gain = std::max(out.stopband_gain, std::abs(h));
    }
  };
  // Every side lobe within 40 lobe widths of each edge at 32 points per lobe (a lobe peak is then
  // missed by < 0.5 %), coarser elsewhere where the lobes are far below the bound.
  const double near = 40.0 * lobe, fine = lobe / 32.0;
  scan(std::max(0.0, s.passband_hz - near), s.passband_hz, fine, true);
  scan(0.0, s.passband_hz, std::max(fine, s.passband_hz / 1000.0), true);
  scan(s.stopband_hz, std::min(nyq, s.stopband_hz + near), fine, false);
  scan(s.stopband_hz, nyq, std::max(fine, (nyq - s.stopband_hz) / 2000.0), false);
  return out;
}

std::vector<double> designKaiserLowpass(const LowpassSpec& spec) {
  throwIfInvalid("low-pass design", spec.validate());
  // 1 % margin covers the grid's sampling of the lobe peaks.
  const double delta = 0.99 * std::pow(10.0, -spec.attenuation_db / 20.0);
  size_t n = kaiserLength(spec);
  for (int iter = 0; iter < 40; ++iter) {
    if (n > static_cast<size_t>(spec.max_taps)) break;
    std::vector<double> h = kaiserSinc(spec, n);
    const LowpassCheck c = checkLowpass(h, spec);
    if (c.passband_deviation <= delta && c.stopband_gain <= delta) return h;
    n = (static_cast<size_t>(double(n) * 1.02) + 2) | 1u;
  }
  std::ostringstream m;
  m << "low-pass design: " << spec.attenuation_db << " dB between " << spec.passband_hz << " and "
    << spec.stopband_hz << " Hz at " << spec.sample_rate_hz << " Hz needs more than "
    << spec.max_taps << " taps";
  throw InputError(m.str());
}

PolyphaseDecimator4::PolyphaseDecimator4(std::vector<double> taps, int decimation)
    : taps_(std::move(taps)), decimation_(decimation) {
  const size_t n = taps_.size();
  if (n < 1 || n % 2 == 0) throw InputError("PolyphaseDecimator4: the number of taps must be odd");
  for (size_t k = 0; k < n / 2; ++k)
    if (taps_[k] != taps_[n - 1 - k]) throw InputError("PolyphaseDecimator4: taps not symmetric");
  if (decimation < 1) throw InputError("PolyphaseDecimator4: decimation must be >= 1");
  half_taps_.assign(taps_.begin(), taps_.begin() + n / 2);
  chunk_ = std::max<size_t>(4096, 4 * static_cast<size_t>(decimation));
  buf_.resize(4 * (n - 1 + chunk_));
  times_.resize(n - 1 + chunk_);
  reset();
}

void PolyphaseDecimator4::reset() {
  len_ = 0;
  next_end_ = taps_.size() - 1;
}

void PolyphaseDecimator4::compact() {
  const size_t n = taps_.size();
  const size_t start = next_end_ + 1 - n;  // first sample still needed
  const size_t drop = std::min(start, len_);
  if (drop == 0) return;
  std::memmove(buf_.data(), buf_.data() + 4 * drop, sizeof(double) * 4 * (len_ - drop));
  std::memmove(times_.data(), times_.data() + drop, sizeof(double) * (len_ - drop));
  len_ -= drop;
  next_end_ -= drop;
}

PolyphaseDecimator4::InputSlot PolyphaseDecimator4::prepareInput(size_t n) {
  if (n > chunk_) throw InputError("PolyphaseDecimator4: chunk too large");
  if (len_ + n > times_.size()) compact();
  return {buf_.data() + 4 * len_, times_.data() + len_};
}

void PolyphaseDecimator4::commit(size_t n, std::vector<double>& out_values,
                                 std::vector<double>& out_times) {
  len_ += n;
  const size_t nt = taps_.size(), half = nt / 2;
  const double centre = taps_[half];
  while (next_end_ < len_) {
    const size_t start = next_end_ + 1 - nt;
    double y[4];
    symmetricDot4(half_taps_.data(), half, centre, buf_.data() + 4 * start, nt, y);
    out_values.insert(out_values.end(), y, y + 4);
    out_times.push_back(times_[start + half]);
    next_end_ += static_cast<size_t>(decimation_);
  }
}

void PolyphaseDecimator4::push(const double* values, const double* times, size_t n,
                               std::vector<double>& out_values, std::vector<double>& out_times) {
  while (n > 0) {
    const size_t k = std::min(n, chunk_);
    const InputSlot slot = prepareInput(k);
    std::memcpy(slot.values, values, sizeof(double) * 4 * k);
    std::memcpy(slot.times, times, sizeof(double) * k);
    commit(k, out_values, out_times);
    values += 4 * k;
    times += k;
    n -= k;
  }
}

}  // namespace cvg_bench
