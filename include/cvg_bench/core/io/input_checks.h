// Checks on inputs before any arithmetic: files that can be read and written, and physical ranges
// of the recorded values (interfaces.md "Input files"). Every failure is an InputError whose
// message names the file (and line and column where the caller knows them), the quantity and its
// unit.
//
// Why magnitudes are bounded: the regressors hold cubes and fifth powers of the states (cubic and
// quintic stiffness, docs/paper.md), so a finite 1e300 overflows to Inf inside the solvers. A value
// far beyond the record's own scale is a corrupted sample, not physics.
#pragma once

#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace cvg_bench {

/// Largest accepted natural or reference frequency [rad/s] (about 1.6 GHz).
constexpr double kMaxOmegaRadS = 1e10;
/// Largest accepted |state| or |raw signal| value [record units]: its fifth power stays finite.
constexpr double kMaxStateMagnitude = 1e30;
/// A state value more than this many times the record's typical magnitude (median over rows of the
/// largest |state| in the row) is rejected as a corrupted sample.
constexpr double kMaxStateOverTypical = 1e6;
/// Largest accepted |time stamp| [s] (epoch stamps are ~1.7e9 s).
constexpr double kMaxTimeS = 1e12;
/// An interval between consecutive time stamps more than this many times the median interval is a
/// jump in the clock, not a gap in the data.
constexpr double kMaxIntervalOverMedian = 1e4;

/// "prefix" for a row and column of the input ("file:line:col: "), supplied by the reader.
using RowLocator = std::function<std::string(size_t row, const std::string& column)>;

/// omega [rad/s] must be finite, > 0 and <= kMaxOmegaRadS; `what` names the source (option, file).
void requireOmegaInRange(double omega_rad_s, const std::string& what);

/// The path exists and is a regular file that can be opened (not a directory).
void requireInputFile(const std::string& path, const std::string& what);
/// The path is not a directory and its parent directory exists and is writable.
void requireOutputFile(const std::string& path, const std::string& what);

/// State (or raw signal) columns: |x| <= kMaxStateMagnitude and <= kMaxStateOverTypical times the
/// record's typical magnitude. The columns have equal lengths.
void checkStateColumns(const std::vector<std::pair<std::string, const std::vector<double>*>>& cols,
                       const RowLocator& where);
/// A time column (already in increasing order): |t| <= kMaxTimeS, no interval above
/// kMaxIntervalOverMedian times the median interval.
void checkTimeColumn(const std::vector<double>& t_s, const std::string& name,
                     const RowLocator& where);
/// Sweep excitation frequencies: each omega0 finite, > 0 and <= kMaxOmegaRadS.
void checkExcitationColumn(const std::vector<double>& omega0_rad_s, const std::string& name,
                           const RowLocator& where);

}  // namespace cvg_bench
