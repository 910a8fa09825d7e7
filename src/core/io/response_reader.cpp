// Reader and writer of one-mode frequency-response files (response_record.h).
#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <map>
#include <ostream>
#include <sstream>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/io/response_record.h"

namespace cvg_bench {
namespace {

const char* const kKeys[] = {"t", "frequency_hz", "x", "y", "drive", "direction"};

std::string lowerTrimmed(const std::string& s) {
  size_t a = 0, b = s.size();
  while (a < b && std::isspace(static_cast<unsigned char>(s[a]))) ++a;
  while (b > a && std::isspace(static_cast<unsigned char>(s[b - 1]))) --b;
  std::string out = s.substr(a, b - a);
  for (auto& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

/// Fields of a data row: split at `,` or `;` when present, else at runs of whitespace (tabs too).
std::vector<std::string> splitRow(const std::string& line) {
  std::vector<std::string> out;
  char sep = 0;
  if (line.find(',') != std::string::npos)
    sep = ',';
  else if (line.find(';') != std::string::npos)
    sep = ';';
  if (sep != 0) {
    std::string cur;
    for (char c : line) {
      if (c == sep) {
        out.push_back(lowerTrimmed(cur));
        cur.clear();
      } else {
        cur += c;
      }
    }
    out.push_back(lowerTrimmed(cur));
    return out;
  }
  std::istringstream ss(line);
  std::string f;
  while (ss >> f) out.push_back(lowerTrimmed(f));
  return out;
}

bool parseNumber(const std::string& field, double& v) {
  if (field.empty()) return false;
  errno = 0;
  char* end = nullptr;
  v = std::strtod(field.c_str(), &end);
  return end != field.c_str() && *end == '\0' && errno != ERANGE;
}

/// A header cell without a bracketed unit, as a key: "x [V]" -> "x". Instruments' own short
/// names are read as the keys they mean (t/time, F/freq/frequency, X/Y, D/drive/current/I).
std::string headerName(const std::string& cell) {
  std::string s = cell.substr(0, cell.find('['));
  s = lowerTrimmed(s.substr(0, s.find('(')));
  static const std::map<std::string, std::string> kAliases = {{"time", "t"},
                                                              {"time_s", "t"},
                                                              {"f", "frequency_hz"},
                                                              {"freq", "frequency_hz"},
                                                              {"frequency", "frequency_hz"},
                                                              {"f_hz", "frequency_hz"},
                                                              {"d", "drive"},
                                                              {"current", "drive"},
                                                              {"i", "drive"},
                                                              {"excitation", "drive"},
                                                              {"dir", "direction"}};
  const auto it = kAliases.find(s);
  return it == kAliases.end() ? s : it->second;
}

/// Four headerless columns: F, X, Y, drive when the fourth is positive and takes at most one
/// distinct value per 5 rows (set drive levels; checked first: a single up sweep also has a
/// first column that never decreases); else t, F, X, Y (one drive level) when the first column
/// never decreases (a clock) while the second turns round (sweeps). Else nothing is guessed.
std::map<std::string, int> guessFourColumns(const std::string& text, std::string* note) {
  std::istringstream in(text);
  std::string line;
  std::vector<std::array<double, 4>> rows;
  while (std::getline(in, line) && rows.size() < 100000) {
    const std::string t = lowerTrimmed(line);
    if (t.empty() || t[0] == '#' || t[0] == '%') continue;
    const std::vector<std::string> f = splitRow(line);
    if (f.size() != 4) return {};
    std::array<double, 4> r{};
    for (int i = 0; i < 4; ++i)
      if (!parseNumber(f[i], r[i]) || !std::isfinite(r[i])) return {};
    rows.push_back(r);
  }
  if (rows.size() < 8) return {};
  bool first_clock = true, second_turns = false, fourth_positive = true;
  int prev_sign = 0;
  std::vector<double> fourth;
  for (size_t i = 0; i < rows.size(); ++i) {
    fourth.push_back(rows[i][3]);
    fourth_positive = fourth_positive && rows[i][3] > 0.0;
    if (i == 0) continue;
    first_clock = first_clock && rows[i][0] >= rows[i - 1][0];
    const double df = rows[i][1] - rows[i - 1][1];
    const int sign = df > 0 ? 1 : (df < 0 ? -1 : 0);
    if (sign != 0 && prev_sign != 0 && sign != prev_sign) second_turns = true;
    if (sign != 0) prev_sign = sign;
  }
  std::sort(fourth.begin(), fourth.end());
  const size_t distinct =
      static_cast<size_t>(std::unique(fourth.begin(), fourth.end()) - fourth.begin());
  if (fourth_positive && distinct * 5 <= rows.size()) {
    *note =
        "no header and no --columns: 4 columns read as frequency_hz, x, y, drive (the fourth "
        "holds " +
        std::to_string(distinct) + " levels)";
    return {{"frequency_hz", 0}, {"x", 1}, {"y", 2}, {"drive", 3}};
  }
  if (first_clock && second_turns) {
    *note =
        "no header and no --columns: 4 columns read as t, frequency_hz, x, y (the first never "
        "decreases, the second turns round); one drive level";
    return {{"t", 0}, {"frequency_hz", 1}, {"x", 2}, {"y", 3}};
  }
  return {};
}

std::string knownKeys() {
  std::string s;
  for (const char* k : kKeys) s += std::string(s.empty() ? "" : ", ") + k;
  return s;
}

/// "t=1,frequency_hz=2,..." -> key -> 0-based column.
std::map<std::string, int> parseColumnMap(const std::string& spec) {
  std::map<std::string, int> out;
  std::stringstream ss(spec);
  std::string item;
  while (std::getline(ss, item, ',')) {
    if (item.empty()) continue;
    const size_t eq = item.find('=');
    if (eq == std::string::npos)
      throw InputError("--columns: '" + item + "' is not KEY=N (1-based column number)");
    const std::string key = lowerTrimmed(item.substr(0, eq));
    if (std::find(std::begin(kKeys), std::end(kKeys), key) == std::end(kKeys))
      throw InputError("--columns: unknown key '" + key + "' (known: " + knownKeys() + ")");
    double n = 0;
    if (!parseNumber(lowerTrimmed(item.substr(eq + 1)), n) || n < 1 || n != std::floor(n) ||
        n > 1000)
      throw InputError("--columns: '" + item + "': the column must be a number from 1");
    if (!out.emplace(key, static_cast<int>(n) - 1).second)
      throw InputError("--columns: key '" + key + "' given twice");
  }
  for (const char* k : {"frequency_hz", "x", "y"})
    if (!out.count(k)) throw InputError(std::string("--columns: key '") + k + "' is required");
  return out;
}

int directionOf(const std::string& field, double& num) {
  if (field == "up" || field == "+") return 1;
  if (field == "down" || field == "-") return -1;
  if (parseNumber(field, num) && std::isfinite(num)) return num > 0 ? 1 : (num < 0 ? -1 : 0);
  return 2;  // unparsable
}

/// Header row (step 2a): the named columns it holds; frequency_hz, x and y are required.
void readHeaderRow(const std::vector<std::string>& fields, const std::string& where, int line_no,
                   bool have_map, std::map<std::string, int>* col) {
  if (have_map)
    throw InputError(where + std::to_string(line_no) +
                     ": the file has a header row; --columns is for headerless files");
  for (size_t i = 0; i < fields.size(); ++i) {
    const std::string name = headerName(fields[i]);
    if (std::find(std::begin(kKeys), std::end(kKeys), name) != std::end(kKeys))
      col->emplace(name, static_cast<int>(i));
  }
  for (const char* k : {"frequency_hz", "x", "y"})
    if (!col->count(k))
      throw InputError(where + std::to_string(line_no) + ": no column '" + k +
                       "' in the header (named columns: " + knownKeys() +
                       "; headerless files: --columns t=1,frequency_hz=2,x=3,y=4,drive=5)");
}

/// No header and no --columns (step 2b): the columns guessed from their count (and, for four,
/// from what they hold: guessFourColumns), with a note saying how they were read.
void guessHeaderlessColumns(const std::vector<std::string>& fields, const std::string& text,
                            const std::string& where, int line_no, std::map<std::string, int>* col,
                            ResponseRecord* rec) {
  std::string guess_note;
  if (fields.size() >= 5) {
    *col = {{"t", 0}, {"frequency_hz", 1}, {"x", 2}, {"y", 3}, {"drive", 4}};
    rec->notes.push_back(
        "no header and no --columns: columns read as t, frequency_hz, x, y, drive");
  } else if (fields.size() == 4 && !(*col = guessFourColumns(text, &guess_note)).empty()) {
    rec->notes.push_back(guess_note);
  } else if (fields.size() == 3) {
    *col = {{"frequency_hz", 0}, {"x", 1}, {"y", 2}};
    rec->notes.push_back(
        "no header and no --columns: columns read as frequency_hz, x, y (one drive level)");
  } else {
    throw InputError(where + std::to_string(line_no) + ": " + std::to_string(fields.size()) +
                     " columns and no header: give --columns t=N,frequency_hz=N,x=N,y=N,"
                     "drive=N");
  }
}

/// The finite number in the row's column of `key`.
void readField(const std::vector<std::string>& fields, const std::map<std::string, int>& col,
               const char* key, const std::string& where, int line_no, double& v) {
  const int c = col.at(key);
  if (c >= static_cast<int>(fields.size()))
    throw InputError(where + std::to_string(line_no) + ": no field " + std::to_string(c + 1) +
                     " (" + key + "); the row has " + std::to_string(fields.size()));
  if (!parseNumber(fields[c], v) || !std::isfinite(v))
    throw InputError(where + std::to_string(line_no) + ": field " + std::to_string(c + 1) + " (" +
                     key + ") is not a finite number: '" + fields[c] + "'");
}

/// One data row (step 3): its values checked (frequency and drive > 0, time never going back,
/// a direction when the column is there) and appended to `rec`; equal time stamps counted.
void readDataRow(const std::vector<std::string>& fields, const std::map<std::string, int>& col,
                 const std::string& where, int line_no, ResponseRecord* rec, size_t* time_ties) {
  double f = 0, x = 0, y = 0, d = 1.0, tt = static_cast<double>(rec->size());
  readField(fields, col, "frequency_hz", where, line_no, f);
  readField(fields, col, "x", where, line_no, x);
  readField(fields, col, "y", where, line_no, y);
  if (col.count("drive")) readField(fields, col, "drive", where, line_no, d);
  if (col.count("t")) readField(fields, col, "t", where, line_no, tt);
  if (!(f > 0))
    throw InputError(where + std::to_string(line_no) + ": frequency_hz must be > 0, got " +
                     fields[col.at("frequency_hz")]);
  if (!(d > 0))
    throw InputError(where + std::to_string(line_no) +
                     ": drive must be > 0 (a drive level per point), got " +
                     fields[col.at("drive")]);
  // Equal stamps are a coarse clock (the file's order is the time order); a stamp going back
  // is two records joined or a wrong column.
  if (!rec->t_s.empty() && tt < rec->t_s.back())
    throw InputError(where + std::to_string(line_no) +
                     ": time must increase (the file is read in time order), got " +
                     std::to_string(tt) + " after " + std::to_string(rec->t_s.back()));
  if (!rec->t_s.empty() && tt == rec->t_s.back()) ++*time_ties;
  if (col.count("direction")) {
    const int c = col.at("direction");
    double num = 0;
    const int dir = c < static_cast<int>(fields.size()) ? directionOf(fields[c], num) : 2;
    if (dir == 2)
      throw InputError(where + std::to_string(line_no) + ": field " + std::to_string(c + 1) +
                       " (direction) must be up/down or a signed number");
    rec->direction.push_back(dir);
  }
  rec->t_s.push_back(tt);
  rec->frequency_hz.push_back(f);
  rec->x.push_back(x);
  rec->y.push_back(y);
  rec->drive.push_back(d);
}

/// After the last row (step 4): notes on the clock and the drive, and the fit's minimum.
void finishRecord(const std::map<std::string, int>& col, size_t time_ties,
                  const std::string& source, ResponseRecord* rec) {
  rec->has_time = col.count("t") > 0;
  if (time_ties > 0)
    rec->notes.push_back(std::to_string(time_ties) +
                         " points share the time stamp of the point before (a coarse clock); the "
                         "file's order is taken as the time order");
  if (!col.count("drive") && rec->size() > 0)
    rec->notes.push_back("no drive column: one drive level (1) assumed");
  if (rec->size() < kMinResponsePoints)
    throw InputError(source + ": " + std::to_string(rec->size()) +
                     " response points; a one-mode fit needs at least 8");
}

}  // namespace

ResponseKind parseResponseKind(const std::string& s) {
  if (s == "displacement") return ResponseKind::kDisplacement;
  if (s == "velocity") return ResponseKind::kVelocity;
  throw InputError("--response: '" + s + "' is not displacement or velocity");
}

std::string responseKindName(ResponseKind k) {
  return k == ResponseKind::kVelocity ? "velocity" : "displacement";
}

ResponseRecord readResponseText(const std::string& text, const std::string& source,
                                const std::string& columns) {
  ResponseRecord rec;
  rec.source = source;
  // 1. The columns from --columns, if given.
  std::map<std::string, int> col;
  bool have_map = false;
  if (!columns.empty()) {
    col = parseColumnMap(columns);
    have_map = true;
  }
  std::istringstream in(text);
  std::string line;
  int line_no = 0;
  bool first_row = true;
  size_t time_ties = 0;
  const std::string where = source + ":";
  while (std::getline(in, line)) {
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const std::string t = lowerTrimmed(line);
    if (t.empty()) continue;
    if (t[0] == '#' || t[0] == '%') {
      rec.comments.push_back(line.substr(line.find_first_of("#%") + 1));
      continue;
    }
    const std::vector<std::string> fields = splitRow(line);
    // 2. The first row: a header, or the first data row of a headerless file.
    if (first_row) {
      first_row = false;
      double v = 0;
      if (!parseNumber(fields[0], v)) {  // a header row
        readHeaderRow(fields, where, line_no, have_map, &col);
        have_map = true;
        continue;
      }
      if (!have_map) {
        guessHeaderlessColumns(fields, text, where, line_no, &col, &rec);
        have_map = true;
      }
    }
    // 3. The row's values.
    readDataRow(fields, col, where, line_no, &rec, &time_ties);
  }
  // 4. Notes and the minimum size.
  finishRecord(col, time_ties, source, &rec);
  return rec;
}

ResponseRecord readResponseFile(const std::string& path, const std::string& columns) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open");
  std::stringstream ss;
  ss << in.rdbuf();
  return readResponseText(ss.str(), path, columns);
}

void writeResponseCsv(const ResponseRecord& r, std::ostream& out) {
  for (const auto& c : r.comments) out << "#" << c << "\n";
  out << "t,frequency_hz,x,y,drive\n" << std::setprecision(12);
  for (size_t i = 0; i < r.size(); ++i)
    out << r.t_s[i] << "," << r.frequency_hz[i] << "," << r.x[i] << "," << r.y[i] << ","
        << r.drive[i] << "\n";
}

std::vector<int> driveLevels(const std::vector<double>& drive) {
  std::vector<size_t> order(drive.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return drive[a] < drive[b]; });
  std::vector<int> level(drive.size(), 0);
  int current = 0;
  double first = order.empty() ? 0.0 : drive[order[0]];
  for (size_t k = 0; k < order.size(); ++k) {
    const double v = drive[order[k]];
    if (std::fabs(v - first) > 0.01 * std::fabs(first)) {
      ++current;
      first = v;
    }
    level[order[k]] = current;
  }
  return level;
}

std::vector<int> splitSweeps(const ResponseRecord& r) {
  const size_t n = r.size();
  std::vector<int> id(n, 0);
  if (n == 0) return id;
  const std::vector<int> level = driveLevels(r.drive);
  std::vector<double> dt;
  for (size_t i = 1; i < n; ++i) dt.push_back(r.t_s[i] - r.t_s[i - 1]);
  double median_dt = 0;
  if (!dt.empty()) {
    std::nth_element(dt.begin(), dt.begin() + dt.size() / 2, dt.end());
    median_dt = dt[dt.size() / 2];
  }
  int sweep = 0;
  int step_sign = 0;  // sign of the frequency steps of the current sweep (0: not yet known)
  for (size_t i = 1; i < n; ++i) {
    const double df = r.frequency_hz[i] - r.frequency_hz[i - 1];
    const int s = df > 0 ? 1 : (df < 0 ? -1 : 0);
    bool cut = level[i] != level[i - 1];
    cut = cut || (s != 0 && step_sign != 0 && s != step_sign);
    cut = cut || (!r.direction.empty() && r.direction[i] != r.direction[i - 1]);
    cut = cut || (median_dt > 0 && r.t_s[i] - r.t_s[i - 1] > 20.0 * median_dt);
    if (cut) {
      ++sweep;
      step_sign = 0;
    } else if (s != 0) {
      step_sign = s;
    }
    id[i] = sweep;
  }
  return id;
}

}  // namespace cvg_bench
