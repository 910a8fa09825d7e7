// Reader and writer of single-channel ring-down CSVs (ringdown_record.h).
#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <ostream>
#include <sstream>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/io/ringdown_record.h"

namespace cvg_bench {
namespace {

std::string trim(const std::string& s) {
  size_t a = 0, b = s.size();
  while (a < b && std::isspace(static_cast<unsigned char>(s[a]))) ++a;
  while (b > a && std::isspace(static_cast<unsigned char>(s[b - 1]))) --b;
  return s.substr(a, b - a);
}

std::string lower(std::string s) {
  for (auto& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

char separatorOf(const std::string& line) {
  if (line.find('\t') != std::string::npos) return '\t';
  if (line.find(';') != std::string::npos) return ';';
  return ',';
}

std::vector<std::string> splitFields(const std::string& line, char sep) {
  std::vector<std::string> out;
  std::string cur;
  for (char c : line) {
    if (c == sep) {
      out.push_back(trim(cur));
      cur.clear();
    } else {
      cur += c;
    }
  }
  out.push_back(trim(cur));
  return out;
}

/// A header cell split into its leading word (lower case, letters/digits/_ only) and the unit in
/// brackets or parentheses (lower case, may be empty).
struct HeaderCell {
  std::string word, unit;
};

HeaderCell parseHeaderCell(const std::string& cell) {
  HeaderCell h;
  const std::string c = lower(trim(cell));
  size_t i = 0;
  while (i < c.size() && (std::isalnum(static_cast<unsigned char>(c[i])) || c[i] == '_')) {
    h.word += c[i];
    ++i;
  }
  const size_t open = c.find_first_of("[(");
  if (open != std::string::npos) {
    const size_t close = c.find_first_of("])", open);
    h.unit =
        trim(c.substr(open + 1, close == std::string::npos ? std::string::npos : close - open - 1));
  }
  return h;
}

enum class ColumnRole { kNone, kTime, kAmplitude, kPowerDb, kRaw };

ColumnRole roleOf(const HeaderCell& h) {
  const bool db_unit = h.unit.rfind("db", 0) == 0;
  if (h.word == "t" || h.word == "time" || h.word == "t_s" || h.word == "time_s")
    return ColumnRole::kTime;
  if (h.word == "power_db" || h.word.rfind("db", 0) == 0 || h.word == "level_db")
    return ColumnRole::kPowerDb;
  if (h.word == "power" || h.word == "level" || h.word == "psd" || h.word == "spectrum")
    return db_unit ? ColumnRole::kPowerDb : ColumnRole::kNone;
  if (h.word == "amplitude" || h.word == "amp" || h.word == "r" || h.word == "mag" ||
      h.word == "magnitude" || h.word == "envelope" || h.word == "a")
    return db_unit ? ColumnRole::kPowerDb : ColumnRole::kAmplitude;
  if (h.word == "f" || h.word == "signal" || h.word == "x" || h.word == "voltage" || h.word == "v")
    return db_unit ? ColumnRole::kPowerDb : ColumnRole::kRaw;
  return ColumnRole::kNone;
}

struct HeaderChoice {
  bool ok = false;
  int time_col = -1, value_col = -1;
  ColumnRole value_role = ColumnRole::kNone;
  std::string value_name;
  char sep = ',';
};

HeaderChoice chooseColumns(const std::string& line) {
  HeaderChoice hc;
  hc.sep = separatorOf(line);
  const auto cells = splitFields(line, hc.sep);
  // Priority of value columns: amplitude, then dB power, then raw waveform.
  int best_rank = 99;
  for (size_t i = 0; i < cells.size(); ++i) {
    const ColumnRole r = roleOf(parseHeaderCell(cells[i]));
    if (r == ColumnRole::kTime && hc.time_col < 0) hc.time_col = static_cast<int>(i);
    const int rank = r == ColumnRole::kAmplitude ? 0
                     : r == ColumnRole::kPowerDb ? 1
                     : r == ColumnRole::kRaw     ? 2
                                                 : 99;
    if (rank < best_rank) {
      best_rank = rank;
      hc.value_col = static_cast<int>(i);
      hc.value_role = r;
      hc.value_name = cells[i];
    }
  }
  hc.ok = hc.time_col >= 0 && hc.value_col >= 0;
  return hc;
}

bool parseNumber(const std::string& field, double& v) {
  const std::string f = trim(field);
  if (f.empty()) return false;
  errno = 0;
  char* end = nullptr;
  v = std::strtod(f.c_str(), &end);
  return end != f.c_str() && *end == '\0';
}

/// `key: value` or `key = value` in a comment; returns false when the comment is free text.
bool parseKey(const std::string& comment, std::string& key, std::string& value) {
  size_t pos = comment.find(':');
  if (pos == std::string::npos) pos = comment.find('=');
  if (pos == std::string::npos) return false;
  key = lower(trim(comment.substr(0, pos)));
  value = trim(comment.substr(pos + 1));
  return !key.empty();
}

}  // namespace

RingdownRecord readRingdownCsvText(const std::string& text, const std::string& source_name) {
  RingdownRecord rec;
  rec.source = source_name;
  std::istringstream in(text);
  std::string line;
  int line_no = 0;
  HeaderChoice header;
  HeaderChoice comment_header;
  double omega_key = 0.0;
  std::vector<std::pair<std::string, int>> data_lines;
  while (std::getline(in, line)) {
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const std::string t = trim(line);
    if (t.empty()) continue;
    if (t[0] == '#' || t[0] == '%') {
      const std::string c = trim(t.substr(1));
      rec.comments.push_back(c);
      std::string key, value;
      if (parseKey(c, key, value)) {
        const HeaderCell kc = parseHeaderCell(key);
        double v = 0.0;
        const bool is_freq = key == "frequency_hz" ||
                             (kc.word == "frequency" && (kc.unit == "hz" || kc.unit.empty())) ||
                             key == "f0_hz" || key == "frequency";
        if ((is_freq || key == "omega" || kc.word == "omega") && !parseNumber(value, v))
          throw InputError(source_name + ":" + std::to_string(line_no) + ": key '" + key +
                           "' needs a number, got '" + value + "'");
        if (is_freq) {
          requirePositive(v, source_name + ":" + std::to_string(line_no) + ": frequency_hz");
          rec.frequency_hz = v;
        } else if (key == "omega" || kc.word == "omega") {
          requirePositive(v, source_name + ":" + std::to_string(line_no) + ": omega");
          omega_key = v;
        }
      } else {
        const HeaderChoice hc = chooseColumns(c);
        if (hc.ok) comment_header = hc;
      }
      continue;
    }
    if (!header.ok && data_lines.empty()) {
      double probe = 0.0;
      const char sep = separatorOf(t);
      const auto cells = splitFields(t, sep);
      if (!parseNumber(cells.front(), probe)) {
        header = chooseColumns(t);
        if (!header.ok)
          throw InputError(source_name + ":" + std::to_string(line_no) +
                           ": header row needs a time column (t, time [s]) and a value column "
                           "(amplitude, power_db / power [dBm], or f for a raw waveform), got '" +
                           t + "'");
        continue;
      }
    }
    data_lines.emplace_back(t, line_no);
  }
  if (!header.ok) header = comment_header;
  if (!header.ok)
    throw InputError(source_name +
                     ": no header row naming the columns (t and amplitude, power_db or f)");
  if (rec.frequency_hz <= 0.0 && omega_key > 0.0) rec.frequency_hz = omega_key / (2.0 * M_PI);
  rec.kind = header.value_role == ColumnRole::kAmplitude ? RingdownValueKind::kAmplitude
             : header.value_role == ColumnRole::kPowerDb ? RingdownValueKind::kPowerDb
                                                         : RingdownValueKind::kRawWaveform;
  rec.value_column = header.value_name;
  const int need = std::max(header.time_col, header.value_col) + 1;
  for (const auto& dl : data_lines) {
    const auto cells = splitFields(dl.first, header.sep);
    const std::string where = source_name + ":" + std::to_string(dl.second);
    if (static_cast<int>(cells.size()) < need)
      throw InputError(where + ": " + std::to_string(cells.size()) + " fields, the header needs " +
                       std::to_string(need));
    double t = 0.0, v = 0.0;
    if (!parseNumber(cells[header.time_col], t) || !std::isfinite(t))
      throw InputError(where + ": column " + std::to_string(header.time_col + 1) +
                       " (time): not a finite number: '" + cells[header.time_col] + "'");
    if (!parseNumber(cells[header.value_col], v))
      throw InputError(where + ": column " + std::to_string(header.value_col + 1) + " (" +
                       header.value_name + "): not a number: '" + cells[header.value_col] + "'");
    if (!rec.t_s.empty() && !(t > rec.t_s.back()))
      throw InputError(where + ": column " + std::to_string(header.time_col + 1) +
                       " (time): " + std::to_string(t) + " s is not after the previous row's " +
                       std::to_string(rec.t_s.back()) + " s");
    rec.t_s.push_back(t);
    rec.value.push_back(v);
  }
  if (rec.size() < 8)
    throw InputError(source_name + ": only " + std::to_string(rec.size()) +
                     " data rows; a ring-down needs at least 8");
  return rec;
}

RingdownRecord readRingdownCsv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError("cannot open '" + path + "'");
  std::stringstream ss;
  ss << in.rdbuf();
  return readRingdownCsvText(ss.str(), path);
}

void writeRingdownCsv(const RingdownRecord& record, std::ostream& out) {
  out << std::setprecision(12);
  if (record.frequency_hz > 0.0) out << "# frequency_hz: " << record.frequency_hz << "\n";
  for (const auto& c : record.comments)
    if (c.rfind("frequency_hz", 0) != 0) out << "# " << c << "\n";
  const char* name = record.kind == RingdownValueKind::kAmplitude ? "amplitude"
                     : record.kind == RingdownValueKind::kPowerDb ? "power_db"
                                                                  : "f";
  out << "t," << name << "\n";
  for (size_t i = 0; i < record.size(); ++i) out << record.t_s[i] << "," << record.value[i] << "\n";
}

}  // namespace cvg_bench
