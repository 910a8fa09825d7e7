// Free decays joined for one fit (see record_stacking.h).
#include "cvg_bench/core/io/record_stacking.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "cvg_bench/core/model/errors.h"

namespace cvg_bench {
namespace {

std::string nameOf(const SlowRecord& r, size_t k) {
  return r.source.empty() ? "record " + std::to_string(k + 1) : r.source;
}

double medianStep(const SlowRecord& r) {
  std::vector<double> dt;
  for (size_t i = 1; i < r.t_s.size(); ++i) dt.push_back(r.t_s[i] - r.t_s[i - 1]);
  if (dt.empty()) return 0.0;
  std::nth_element(dt.begin(), dt.begin() + dt.size() / 2, dt.end());
  return dt[dt.size() / 2];
}

}  // namespace

SlowRecord stackFreeDecays(const std::vector<SlowRecord>& records, std::vector<std::string>& notes,
                           double gap_steps) {
  if (records.empty()) throw InputError("no free-decay record to stack");
  if (records.size() == 1) return records.front();
  double step = 0.0;
  for (size_t k = 0; k < records.size(); ++k) {
    const SlowRecord& r = records[k];
    if (r.size() < 2) throw InputError(nameOf(r, k) + ": under two samples, nothing to stack");
    const double w0 = records.front().omega_rad_s, w = r.omega_rad_s;
    if (std::fabs(w - w0) > 1e-9 * std::max(std::fabs(w0), std::fabs(w)))
      throw InputError(nameOf(r, k) + ": omega " + std::to_string(w) + " rad/s differs from " +
                       nameOf(records.front(), 0) + "'s " + std::to_string(w0) +
                       " rad/s: records of one resonator only are stacked");
    for (size_t j = 0; j < k; ++j)
      if (!r.source.empty() && r.source == records[j].source)
        throw InputError(r.source +
                         ": given twice; a record counted twice would narrow every interval as if "
                         "it were new data");
    step = std::max(step, medianStep(r));
  }
  SlowRecord out;
  out.omega_rad_s = records.front().omega_rad_s;
  out.metadata = records.front().metadata;
  out.metadata["stacked_records"] = std::to_string(records.size());
  bool same_extra = true;
  for (const auto& r : records) {
    if (r.extra.size() != records.front().extra.size()) same_extra = false;
    for (const auto& kv : records.front().extra) same_extra &= r.extra.count(kv.first) > 0;
  }
  std::ostringstream names;
  for (size_t k = 0; k < records.size(); ++k) {
    const SlowRecord& r = records[k];
    const double shift = k == 0 ? 0.0 : out.t_s.back() + gap_steps * step - r.t_s.front();
    for (size_t i = 0; i < r.size(); ++i) {
      out.t_s.push_back(r.t_s[i] + shift);
      out.q.push_back(r.q[i]);
    }
    if (same_extra)
      for (const auto& kv : r.extra) {
        auto& col = out.extra[kv.first];
        col.insert(col.end(), kv.second.begin(), kv.second.end());
      }
    names << (k ? ", " : "") << nameOf(r, k);
  }
  out.source = names.str();
  std::ostringstream note;
  note << records.size() << " free decays stacked for one fit (" << names.str() << "): each starts "
       << gap_steps
       << " sample steps after the previous one ends, and the equations across the joins are "
          "left out; a term that depends on absolute time (cm_rate) sees the shifted clock";
  if (!same_extra) note << "; extra columns dropped (not in every record)";
  notes.push_back(note.str());
  return out;
}

}  // namespace cvg_bench
