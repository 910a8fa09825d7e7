#include "cvg_bench/core/io/input_checks_bag.h"

#include <cstring>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <vector>

#include "cvg_bench/core/common/errors.h"

namespace cvg_bench {
namespace {

constexpr char kMagic[] = "#ROSBAG V2.0\n";
constexpr uint8_t kOpMessageData = 0x02, kOpBagHeader = 0x03, kOpIndexData = 0x04, kOpChunk = 0x05,
                  kOpChunkInfo = 0x06, kOpConnection = 0x07;

struct Walker {
  std::ifstream in;
  std::string path;
  std::set<uint64_t> starts;          ///< offsets of the file's top-level records
  std::vector<uint64_t> must_start;   ///< offsets the index points at
  bool seen_chunk = false;            ///< an index data record follows the chunk it indexes
  std::map<uint64_t, int> chunk_ops;  ///< last chunk: record offset in its data -> op

  [[noreturn]] void fail(uint64_t at, const std::string& what) {
    std::ostringstream m;
    m << path << ": byte " << at << ": " << what << " (truncated or corrupt bag)";
    throw InputError(m.str());
  }

  std::string read(uint64_t at, uint64_t n) {
    std::string s(n, '\0');
    in.seekg(static_cast<std::streamoff>(at));
    if (n > 0 && !in.read(&s[0], static_cast<std::streamsize>(n))) fail(at, "cannot read");
    return s;
  }

  uint32_t u32(uint64_t at) {
    const std::string b = read(at, 4);
    return static_cast<uint32_t>(static_cast<uint8_t>(b[0])) |
           static_cast<uint32_t>(static_cast<uint8_t>(b[1])) << 8 |
           static_cast<uint32_t>(static_cast<uint8_t>(b[2])) << 16 |
           static_cast<uint32_t>(static_cast<uint8_t>(b[3])) << 24;
  }

  static uint64_t le(const std::string& v) {
    uint64_t x = 0;
    for (size_t i = v.size(); i-- > 0;) x = (x << 8) | static_cast<uint8_t>(v[i]);
    return x;
  }

  /// A list of "name=value" fields, each after its 4-byte length (record headers, and the
  /// connection header stored as a connection record's data), starting at file offset `at`.
  std::vector<std::pair<std::string, std::string>> fields(uint64_t at, const std::string& bytes) {
    std::vector<std::pair<std::string, std::string>> out;
    for (size_t f = 0; f < bytes.size();) {
      if (bytes.size() - f < 4) fail(at + f, "header field cut short");
      const uint64_t n = le(bytes.substr(f, 4));
      if (n > bytes.size() - f - 4)
        fail(at + f, "header field length " + std::to_string(n) + " beyond the header");
      const std::string field = bytes.substr(f + 4, n);
      const size_t eq = field.find('=');
      if (eq == std::string::npos) fail(at + f, "header field without '='");
      out.emplace_back(field.substr(0, eq), field.substr(eq + 1));
      f += 4 + n;
    }
    return out;
  }

  /// An index data record (version 1: count x {time 8 bytes, offset 4 bytes}): each offset must
  /// start a message data record of the chunk before it (rosbag reads there without a bounds
  /// check: fuzzing found a SEGV in readHeaderFromBuffer).
  void checkIndexData(uint64_t pos, uint64_t data_at, uint64_t data_len, uint64_t ver,
                      uint64_t count) {
    if (!seen_chunk) fail(pos, "index data before any chunk");
    if (ver != 1) fail(pos, "index data version " + std::to_string(ver) + " (only 1 is known)");
    if (data_len != count * 12)
      fail(pos, "index data of " + std::to_string(count) + " entries in " +
                    std::to_string(data_len) + " bytes");
    const std::string d = read(data_at, data_len);
    for (uint64_t i = 0; i < count; ++i) {
      const uint64_t off = le(d.substr(i * 12 + 8, 4));
      const auto it = chunk_ops.find(off);
      if (it == chunk_ops.end() || it->second != kOpMessageData)
        fail(data_at + i * 12, "the index points at chunk offset " + std::to_string(off) +
                                   ", which starts no message record");
    }
  }

  /// Walks the records in [begin, end); top = the file's top level (not inside a chunk).
  void walk(uint64_t begin, uint64_t end, bool top) {
    uint64_t pos = begin;
    while (pos < end) {
      if (top) starts.insert(pos);
      if (end - pos < 4) fail(pos, "record cut short");
      const uint64_t header_len = u32(pos);
      if (header_len > end - pos - 4)
        fail(pos, "record header length " + std::to_string(header_len) + " bytes beyond the end");
      const std::string header = read(pos + 4, header_len);
      uint64_t data_at = pos + 4 + header_len;
      if (end - data_at < 4) fail(data_at, "record data length cut short");
      const uint64_t data_len = u32(data_at);
      data_at += 4;
      if (data_len > end - data_at)
        fail(pos, "record data length " + std::to_string(data_len) + " bytes beyond the end");
      int op = -1;
      std::string compression;
      uint64_t chunk_size = 0, index_pos = 0, chunk_pos = 0, ver = 0, count = 0;
      bool has_size = false, has_index_pos = false, has_chunk_pos = false, has_count = false;
      for (const auto& nv : fields(pos + 4, header)) {
        const std::string &name = nv.first, &value = nv.second;
        if (name == "op" && value.size() == 1) op = static_cast<uint8_t>(value[0]);
        if (name == "compression") compression = value;
        if (name == "size" && value.size() == 4) chunk_size = le(value), has_size = true;
        if (name == "index_pos" && value.size() == 8) index_pos = le(value), has_index_pos = true;
        if (name == "chunk_pos" && value.size() == 8) chunk_pos = le(value), has_chunk_pos = true;
        if (name == "ver" && value.size() == 4) ver = le(value);
        if (name == "count" && value.size() == 4) count = le(value), has_count = true;
      }
      if (!top) chunk_ops[pos - begin] = op;
      if (op == kOpIndexData) {
        if (!top) fail(pos, "index data inside a chunk");
        if (!has_count) fail(pos, "index data without its count");
        checkIndexData(pos, data_at, data_len, ver, count);
      }
      if (op == kOpConnection) fields(data_at, read(data_at, data_len));
      if (op == kOpBagHeader && top && has_index_pos && index_pos != 0)
        must_start.push_back(index_pos);
      if (op == kOpChunkInfo && has_chunk_pos) must_start.push_back(chunk_pos);
      if (op == kOpChunk) {
        if (!top) fail(pos, "chunk inside a chunk");
        if (!has_size) fail(pos, "chunk without its size");
        if (compression != "none")  // its records cannot be checked without decompressing
          fail(pos, "chunk compressed with '" + compression +
                        "' (not read: decompress the bag first, `rosbag decompress`)");
        if (chunk_size != data_len)
          fail(pos, "uncompressed chunk size differs from its data length");
        if (chunk_size > kMaxBagChunkBytes)
          fail(pos, "chunk of " + std::to_string(chunk_size) + " bytes (limit " +
                        std::to_string(kMaxBagChunkBytes) + ")");
        chunk_ops.clear();
        seen_chunk = true;
        walk(data_at, data_at + data_len, false);
      }
      pos = data_at + data_len;
    }
  }
};

}  // namespace

void requireBagStructure(const std::string& path) {
  Walker w;
  w.path = path;
  w.in.open(path, std::ios::binary);
  if (!w.in) throw InputError(path + ": cannot open the bag");
  w.in.seekg(0, std::ios::end);
  const std::streamoff size = w.in.tellg();
  // rosbag accepts any first line "#ROS<word> V<major>.<minor>" and copies <word> into a 100-byte
  // buffer (fuzzing: "#ROSB#ROSBAAG V2.0" passed it, then its header parser read past a record):
  // only the exact format 2.0 line goes on.
  const size_t magic_len = std::strlen(kMagic);
  if (size < static_cast<std::streamoff>(magic_len) || w.read(0, magic_len) != kMagic)
    throw InputError(path + ": not a ROS bag of format 2.0 (the first line is not '#ROSBAG V2.0')");
  w.walk(magic_len, static_cast<uint64_t>(size), true);
  w.starts.insert(static_cast<uint64_t>(size));  // an empty bag's index starts at the end
  for (uint64_t at : w.must_start)
    if (!w.starts.count(at)) w.fail(at, "the index points inside a record");
}

}  // namespace cvg_bench
