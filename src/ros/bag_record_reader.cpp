// rosbag -> core records (see bag_record_reader.h). Message fields are read only through
// conversions.h.
#include "cvg_bench/ros/bag_record_reader.h"

#include <ros/exception.h>
#include <ros/message_traits.h>
#include <rosbag/bag.h>
#include <rosbag/exceptions.h>
#include <rosbag/view.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <map>
#include <numeric>
#include <sstream>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/io/input_checks.h"
#include "cvg_bench/core/io/input_checks_bag.h"
#include "cvg_bench/ros/conversions.h"

namespace cvg_bench {
namespace {

struct TopicInfo {
  std::string type;
  std::string md5;
  size_t count = 0;
};

template <class M>
std::string typeOf() {
  return ros::message_traits::DataType<M>::value();
}

const std::string& typeForKind(RecordKind kind) {
  static const std::string slow = typeOf<SlowState>(), sweep = typeOf<SweepPoint>(),
                           raw = typeOf<RawSampleBatch>();
  return kind == RecordKind::kFreeDecay ? slow : kind == RecordKind::kForcedSweep ? sweep : raw;
}

std::map<std::string, TopicInfo> topicsOf(const rosbag::Bag& bag) {
  std::map<std::string, TopicInfo> topics;
  rosbag::View view(bag);
  for (const rosbag::ConnectionInfo* c : view.getConnections()) {
    TopicInfo& info = topics[c->topic];
    info.type = c->datatype;
    info.md5 = c->md5sum;
  }
  for (auto& kv : topics) kv.second.count = rosbag::View(bag, rosbag::TopicQuery(kv.first)).size();
  return topics;
}

std::string listTopics(const std::map<std::string, TopicInfo>& topics) {
  if (topics.empty()) return "(the bag has no topics)";
  std::ostringstream s;
  for (const auto& kv : topics)
    s << "\n  " << kv.first << "  " << kv.second.type << "  " << kv.second.count << " messages";
  return s.str();
}

std::string kindsText(const std::vector<RecordKind>& kinds) {
  std::string out;
  for (RecordKind k : kinds) out += (out.empty() ? "" : ", ") + typeForKind(k);
  return out;
}

std::string stampText(const ros::Time& t) {
  std::ostringstream s;
  s << t.sec << "." << std::setw(9) << std::setfill('0') << t.nsec;
  return s.str();
}

/// The `# omega:` metadata line a CSV record would carry, at full precision (when omega is known).
void setOmegaMetadata(double omega_rad_s, std::map<std::string, std::string>* metadata) {
  if (!(omega_rad_s > 0.0)) return;
  std::ostringstream s;
  s.precision(17);
  s << omega_rad_s;
  (*metadata)["omega"] = s.str();
}

/// Which topic and kind to read.
std::pair<std::string, RecordKind> chooseTopic(const std::string& path,
                                               const std::map<std::string, TopicInfo>& topics,
                                               const BagReadOptions& options) {
  if (!options.topic.empty()) {
    const auto it = topics.find(options.topic);
    if (it == topics.end())
      throw InputError(path + ": no topic '" + options.topic +
                       "' in the bag; it has:" + listTopics(topics));
    for (RecordKind k : options.kinds)
      if (it->second.type == typeForKind(k)) return {options.topic, k};
    throw InputError(path + ": topic '" + options.topic + "' has type " + it->second.type +
                     ", expected one of: " + kindsText(options.kinds));
  }
  for (RecordKind k : options.kinds) {
    std::vector<std::string> found;
    for (const auto& kv : topics)
      if (kv.second.type == typeForKind(k)) found.push_back(kv.first);
    if (found.size() == 1) return {found.front(), k};
    if (found.size() > 1) {
      std::string names;
      for (const auto& n : found) names += (names.empty() ? "" : ", ") + n;
      throw InputError(path + ": several " + typeForKind(k) + " topics (" + names +
                       "); choose one with --topic NAME");
    }
  }
  throw InputError(path + ": no topic of type " + kindsText(options.kinds) +
                   "; the bag has:" + listTopics(topics));
}

template <class M>
std::vector<typename M::ConstPtr> readAll(const rosbag::Bag& bag, const std::string& path,
                                          const std::string& topic, const TopicInfo& info) {
  if (info.md5 != "*" && info.md5 != ros::message_traits::MD5Sum<M>::value())
    throw InputError(path + ": topic '" + topic + "' holds " + info.type +
                     " with a message definition that differs from this build (md5 " + info.md5 +
                     " vs " + ros::message_traits::MD5Sum<M>::value() + "); re-record the bag");
  std::vector<typename M::ConstPtr> out;
  rosbag::View view(bag, rosbag::TopicQuery(topic));
  for (const rosbag::MessageInstance& m : view) {
    typename M::ConstPtr p = m.instantiate<M>();
    if (!p) throw InputError(path + ": topic '" + topic + "': a message could not be decoded");
    out.push_back(p);
  }
  if (out.empty()) throw InputError(path + ": topic '" + topic + "' has no messages");
  return out;
}

/// Messages missing by header sequence number (a publisher numbers its messages 0, 1, ...; a bag
/// recorded while its recorder's queue overflowed skips numbers). 0 when the bag's messages carry
/// no numbers (all equal) or the numbers restart (a restarted publisher).
template <class Ptr>
uint64_t missingBySequence(const std::vector<Ptr>& msgs) {
  uint64_t missing = 0;
  for (size_t i = 1; i < msgs.size(); ++i) {
    const uint32_t a = msgs[i - 1]->header.seq, b = msgs[i]->header.seq;
    if (b > a) missing += b - a - 1;
  }
  return missing;
}

void noteMissing(uint64_t missing, std::map<std::string, std::string>* metadata) {
  if (missing > 0) (*metadata)["messages_missing_by_sequence"] = std::to_string(missing);
}

std::string where(const std::string& path, const std::string& topic, size_t index) {
  return path + ": topic '" + topic + "' message " + std::to_string(index + 1) + ": ";
}

/// Range checks (input_checks.h) of a record's columns; rows are messages (slow, sweep) or samples.
RowLocator messageLocator(const std::string& path, const std::string& topic) {
  return [path, topic](size_t r, const std::string&) { return where(path, topic, r); };
}
RowLocator sampleLocator(const std::string& path, const std::string& topic) {
  return [path, topic](size_t r, const std::string&) {
    return path + ": topic '" + topic + "' sample " + std::to_string(r + 1) + " (in time order): ";
  };
}
void checkStates(const std::vector<Eigen::Vector4d>& q, const RowLocator& at) {
  std::vector<std::vector<double>> c(4, std::vector<double>(q.size()));
  for (size_t r = 0; r < q.size(); ++r)
    for (int k = 0; k < 4; ++k) c[k][r] = q[r][k];
  checkStateColumns({{"q1", &c[0]}, {"p1", &c[1]}, {"q2", &c[2]}, {"p2", &c[3]}}, at);
}
void checkOmega(double omega_rad_s, const std::string& path, const std::string& topic) {
  if (omega_rad_s != 0.0) requireOmegaInRange(omega_rad_s, path + ": topic '" + topic + "'");
}

void readSlow(const rosbag::Bag& bag, const std::string& path, const std::string& topic,
              const TopicInfo& info, AnyRecord* out) {
  const auto msgs = readAll<SlowState>(bag, path, topic, info);
  SlowRecord& rec = out->slow;
  const ros::Time origin = msgs.front()->header.stamp;
  for (size_t i = 0; i < msgs.size(); ++i) {
    const SlowState& m = *msgs[i];
    Eigen::Vector4d q;
    try {
      q = slowFromMsg(m);
    } catch (const InputError& e) {
      throw InputError(where(path, topic, i) + e.what());
    }
    const double t = secondsSince(m.header.stamp, origin);
    if (!rec.t_s.empty() && !(t > rec.t_s.back()))
      throw InputError(where(path, topic, i) + "stamp " + stampText(m.header.stamp) +
                       " is not after the previous message's (bag looped or recorded twice?)");
    rec.t_s.push_back(t);
    rec.q.push_back(q);
  }
  rec.omega_rad_s = msgs.front()->reference_frequency_rad_s > 0.0
                        ? msgs.front()->reference_frequency_rad_s - msgs.front()->detuning_rad_s
                        : 0.0;
  checkTimeColumn(rec.t_s, "stamp", messageLocator(path, topic));
  checkStates(rec.q, messageLocator(path, topic));
  checkOmega(rec.omega_rad_s, path, topic);
  rec.metadata["mode"] = "free_decay";
  rec.metadata["stamp_origin"] = stampText(origin);
  noteMissing(missingBySequence(msgs), &rec.metadata);
  setOmegaMetadata(rec.omega_rad_s, &rec.metadata);
  rec.source = path;
}

void readSweep(const rosbag::Bag& bag, const std::string& path, const std::string& topic,
               const TopicInfo& info, AnyRecord* out) {
  const auto msgs = readAll<SweepPoint>(bag, path, topic, info);
  SweepRecord& rec = out->sweep;
  for (size_t i = 0; i < msgs.size(); ++i) {
    try {
      appendSweepPoint(*msgs[i], &rec);
    } catch (const InputError& e) {
      throw InputError(where(path, topic, i) + e.what());
    }
  }
  // Points appended before the first flagged one got no flags: align the columns.
  if (!rec.direction.empty() && rec.direction.size() < rec.size()) {
    rec.direction.insert(rec.direction.begin(), rec.size() - rec.direction.size(), 0);
    rec.jump.insert(rec.jump.begin(), rec.size() - rec.jump.size(), 0);
  }
  checkExcitationColumn(rec.omega0_rad_s, "omega0", messageLocator(path, topic));
  checkStates(rec.q, messageLocator(path, topic));
  checkOmega(rec.omega_rad_s, path, topic);
  rec.metadata["mode"] = "forced";
  noteMissing(missingBySequence(msgs), &rec.metadata);
  rec.metadata["stamp_origin"] = stampText(msgs.front()->header.stamp);
  setOmegaMetadata(rec.omega_rad_s, &rec.metadata);
  rec.source = path;
}

void readRaw(const rosbag::Bag& bag, const std::string& path, const std::string& topic,
             const TopicInfo& info, bool repair, AnyRecord* out) {
  const auto msgs = readAll<RawSampleBatch>(bag, path, topic, info);
  RawRecord& rec = out->raw;
  const ros::Time origin =
      msgs.front()->phase_epoch.isZero() ? msgs.front()->header.stamp : msgs.front()->phase_epoch;
  std::vector<double> omega0;
  bool driven = false;
  for (size_t i = 0; i < msgs.size(); ++i) {
    RawSamples s;
    try {
      s = rawSamplesFromMsg(*msgs[i], origin);
    } catch (const InputError& e) {
      throw InputError(where(path, topic, i) + e.what());
    }
    for (size_t j = 0; j < s.t_s.size(); ++j) {
      if (!std::isfinite(s.t_s[j]) || !std::isfinite(s.f[j]) || !std::isfinite(s.g[j]))
        throw InputError(where(path, topic, i) + "sample " + std::to_string(j + 1) +
                         " has a non-finite t, f or g");
    }
    rec.t_s.insert(rec.t_s.end(), s.t_s.begin(), s.t_s.end());
    rec.f.insert(rec.f.end(), s.f.begin(), s.f.end());
    rec.g.insert(rec.g.end(), s.g.begin(), s.g.end());
    omega0.insert(omega0.end(), s.t_s.size(), msgs[i]->drive_frequency_rad_s);
    driven = driven || msgs[i]->drive_frequency_rad_s > 0.0;
    if (rec.omega_rad_s <= 0.0 && msgs[i]->omega_rad_s > 0.0)
      rec.omega_rad_s = msgs[i]->omega_rad_s;
  }
  if (rec.t_s.empty()) throw InputError(path + ": topic '" + topic + "' has no samples");
  // Time order: strict unless repairing (then sort stably and drop repeats, counted).
  bool ordered = true;
  for (size_t i = 1; i < rec.t_s.size() && ordered; ++i) ordered = rec.t_s[i] > rec.t_s[i - 1];
  if (!ordered) {
    if (!repair) {
      for (size_t i = 1; i < rec.t_s.size(); ++i)
        if (!(rec.t_s[i] > rec.t_s[i - 1]))
          throw InputError(path + ": topic '" + topic + "': sample " + std::to_string(i + 1) +
                           " (t = " + std::to_string(rec.t_s[i]) +
                           " s) is not after the previous one; timestamps must increase");
    }
    std::vector<size_t> idx(rec.t_s.size());
    std::iota(idx.begin(), idx.end(), size_t{0});
    std::stable_sort(idx.begin(), idx.end(),
                     [&](size_t a, size_t b) { return rec.t_s[a] < rec.t_s[b]; });
    for (size_t i = 0; i < idx.size(); ++i)
      if (idx[i] != i) ++rec.n_reordered;
    RawRecord sorted;
    std::vector<double> omega0_sorted;
    for (size_t i : idx) {
      if (!sorted.t_s.empty() && rec.t_s[i] == sorted.t_s.back()) {
        ++rec.n_duplicates_dropped;
        continue;
      }
      sorted.t_s.push_back(rec.t_s[i]);
      sorted.f.push_back(rec.f[i]);
      sorted.g.push_back(rec.g[i]);
      omega0_sorted.push_back(omega0[i]);
    }
    rec.t_s.swap(sorted.t_s);
    rec.f.swap(sorted.f);
    rec.g.swap(sorted.g);
    omega0.swap(omega0_sorted);
  }
  checkTimeColumn(rec.t_s, "t", sampleLocator(path, topic));
  checkStateColumns({{"f", &rec.f}, {"g", &rec.g}}, sampleLocator(path, topic));
  checkOmega(rec.omega_rad_s, path, topic);
  if (driven) rec.extra["omega0"] = omega0;
  rec.metadata["mode"] = driven ? "forced" : "free_decay";
  rec.metadata["stamp_origin"] = stampText(origin);
  noteMissing(missingBySequence(msgs), &rec.metadata);
  setOmegaMetadata(rec.omega_rad_s, &rec.metadata);
  rec.source = path;
}

}  // namespace

bool isBagPath(const std::string& path) {
  return path.size() > 4 && path.compare(path.size() - 4, 4, ".bag") == 0;
}

AnyRecord readRecordBag(const std::string& path, const BagReadOptions& options) {
  if (options.kinds.empty()) throw InputError("readRecordBag: no acceptable record kind given");
  requireInputFile(path, "input bag");
  requireBagStructure(path);
  AnyRecord out;
  try {
    rosbag::Bag bag;
    bag.open(path, rosbag::bagmode::Read);
    const auto topics = topicsOf(bag);
    const auto choice = chooseTopic(path, topics, options);
    const TopicInfo& info = topics.at(choice.first);
    out.kind = choice.second;
    if (choice.second == RecordKind::kFreeDecay) {
      readSlow(bag, path, choice.first, info, &out);
      out.slow.metadata["topic"] = choice.first;
      out.slow.metadata["message_type"] = info.type;
    } else if (choice.second == RecordKind::kForcedSweep) {
      readSweep(bag, path, choice.first, info, &out);
      out.sweep.metadata["topic"] = choice.first;
      out.sweep.metadata["message_type"] = info.type;
    } else {
      readRaw(bag, path, choice.first, info, options.repair_raw_timestamps, &out);
      out.raw.metadata["topic"] = choice.first;
      out.raw.metadata["message_type"] = info.type;
    }
  } catch (const rosbag::BagException& e) {
    throw InputError(path + ": not a readable rosbag (missing, truncated or corrupt): " + e.what());
  } catch (const ros::Exception& e) {  // e.g. a message cut short (stream overrun)
    throw InputError(path +
                     ": a message could not be decoded (truncated or corrupt bag): " + e.what());
  }
  return out;
}

std::string describeBagTopics(const std::string& path) {
  requireBagStructure(path);
  try {
    rosbag::Bag bag;
    bag.open(path, rosbag::bagmode::Read);
    return listTopics(topicsOf(bag));
  } catch (const rosbag::BagException& e) {
    throw InputError(path + ": not a readable rosbag (missing, truncated or corrupt): " + e.what());
  }
}

}  // namespace cvg_bench
