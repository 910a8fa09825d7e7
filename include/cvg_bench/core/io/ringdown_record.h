// Single-channel ring-down records (interfaces.md, "Single-channel ring-downs"): one channel of a
// resonator after the drive is switched off, as a lock-in amplifier (linear amplitude), a spectrum
// analyser in zero span (power in dB with any offset: dBm, dBV) or a digitiser (raw waveform t,f)
// writes it. Comment lines start with `#` or `%`; keys `frequency_hz: F`, `Frequency [Hz]: F` or
// `omega: W` (rad/s) give the mode frequency, matched case-insensitively.
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

namespace cvg_bench {

/// dB of power per neper of amplitude, 20 / ln 10: a level P_dB = kDbPerNeper ln A (+ a constant).
inline constexpr double kDbPerNeper = 20.0 / 2.302585092994046;

/// What the value column of a ring-down holds.
enum class RingdownValueKind {
  kAmplitude,    ///< linear amplitude, any unit (> 0; <= 0 or non-finite = drop-out)
  kPowerDb,      ///< power in dB, any offset (20 log10 amplitude + const; -inf/nan = drop-out)
  kRawWaveform,  ///< raw single-channel signal f(t); demodulated before the fit
};

struct RingdownRecord {
  std::vector<double> t_s;    ///< sample times [s], strictly increasing
  std::vector<double> value;  ///< amplitude, power [dB] or raw f, as `kind` says
  RingdownValueKind kind = RingdownValueKind::kAmplitude;
  double frequency_hz = 0.0;  ///< mode frequency [Hz]; 0 when the file does not say
  std::string value_column;   ///< header of the value column as written (e.g. "power [dBm]")
  std::string source;         ///< file name (for messages)
  std::vector<std::string> comments;  ///< comment lines without the leading # or %
  size_t size() const { return t_s.size(); }
};

/// Reads a ring-down CSV. Separators `,` `;` or tab (spaces after them allowed). The header is the
/// first uncommented row; without one, the last comment line that names a time column and a value
/// column. Columns are recognised by their leading word (`t`/`time`; `amplitude`/`amp`/`r`/`mag`
/// /`magnitude`/`envelope`; `power_db`/`power`/`level`/`db*`; `f`/`signal`/`x` for raw) and a
/// bracketed unit (`[dBm]`, `[dBV]`, `[dB]` make a column a dB power). Non-finite values and
/// amplitudes <= 0 are kept (the segmentation treats them as drop-outs). InputError with file,
/// line and column on every problem (unparsable field, missing column, time not increasing).
RingdownRecord readRingdownCsv(const std::string& path);
RingdownRecord readRingdownCsvText(const std::string& text, const std::string& source_name);

/// Writes t and the value column (header `t,amplitude`, `t,power_db` or `t,f`) with
/// `# frequency_hz:` when known.
void writeRingdownCsv(const RingdownRecord& record, std::ostream& out);

}  // namespace cvg_bench
