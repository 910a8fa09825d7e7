// One mode's frequency response as a lock-in or network analyser writes it (docs/interfaces.md,
// "One-mode frequency response"): time, drive frequency, in-phase and quadrature response, drive
// level per point, several drive levels and up/down sweeps in one file, in time order.
#pragma once

#include <cstddef>
#include <iosfwd>
#include <string>
#include <vector>

namespace cvg_bench {

/// Fewest points a response record must hold: the reader refuses fewer, and fitResponse needs as
/// many.
constexpr size_t kMinResponsePoints = 8;

/// What the lock-in sees: the displacement or the velocity (i omega x; e.g. a wire's induced
/// voltage).
enum class ResponseKind { kDisplacement, kVelocity };
ResponseKind parseResponseKind(const std::string& s);  ///< "displacement" | "velocity"
std::string responseKindName(ResponseKind k);

struct ResponseRecord {
  std::vector<double> t_s;           ///< point times [s]; the row index when the file has none
  std::vector<double> frequency_hz;  ///< drive frequency [Hz]
  std::vector<double> x, y;          ///< in-phase and quadrature response (any unit)
  std::vector<double> drive;         ///< drive level per point (any unit, > 0)
  std::vector<int> direction;        ///< +1 up / -1 down from a `direction` column; empty if none
  bool has_time = false;
  std::string source;
  std::vector<std::string> comments;  ///< comment lines without the leading # or %
  std::vector<std::string> notes;     ///< what the reader assumed (column order, unit drive)
  size_t size() const { return frequency_hz.size(); }
};

/// Reads a response file: `,` `;` tab or whitespace separated, `#`/`%` comment lines. Named columns
/// (first uncommented row; case-insensitive, a bracketed unit ignored): `t` (optional),
/// `frequency_hz`, `x`, `y`, `drive` (optional: 1 when absent), `direction` (optional: up/down or
/// +1/-1). Headerless files: `columns` maps keys to 1-based columns ("t=1,frequency_hz=2,x=3,
/// y=4,drive=5"); without it 5 or more columns are read in that order and 3 as frequency_hz,x,y
/// (a note says so). InputError with file, line and field on every problem.
ResponseRecord readResponseFile(const std::string& path, const std::string& columns = "");
ResponseRecord readResponseText(const std::string& text, const std::string& source,
                                const std::string& columns = "");

/// Writes `t,frequency_hz,x,y,drive` with the comments as `#` lines.
void writeResponseCsv(const ResponseRecord& record, std::ostream& out);

/// Drive level of every point (0 = the lowest): the sorted drive values are cut where one exceeds
/// the level's first value by more than 1 %, so a drive that is measured per point (a current
/// read back with its noise) still gives its set levels, not one level per point.
std::vector<int> driveLevels(const std::vector<double>& drive);

/// Sweep index of every point: a new sweep starts where the drive level changes (driveLevels),
/// the frequency step reverses its sign, the `direction` column changes, or time jumps by more
/// than 20 median point intervals. Indices count from 0 in time order.
std::vector<int> splitSweeps(const ResponseRecord& record);

}  // namespace cvg_bench
