// Structure check of a ROS bag (format 2.0) before rosbag opens it. rosbag trusts the lengths and
// offsets stored in the file: a corrupted record length (fuzzing found 2.3e9 bytes in a 17 kB
// bag) makes it allocate that much before it notices the file is shorter. Every record of the file
// is walked here (4-byte header length, header fields, 4-byte data length, data; the records
// inside chunks too) and each length must fit in what remains of the file or chunk; the offsets of
// the index (bag header `index_pos`, chunk info `chunk_pos`) must be the start of a record, and
// each index data entry must point at a message record of the chunk before it; a chunk may not
// exceed kMaxBagChunkBytes. Compressed chunks (bz2, lz4) are refused: their records cannot be
// checked without decompressing (`rosbag decompress` first). Reads headers and index entries.
#pragma once

#include <cstdint>
#include <string>

namespace cvg_bench {

/// Largest accepted uncompressed chunk [bytes] (rosbag's default chunk is 768 kB).
constexpr uint64_t kMaxBagChunkBytes = uint64_t{1} << 30;

/// InputError naming the file and the byte offset of the first record that does not fit, or saying
/// the file is not bag format 2.0 (first line exactly "#ROSBAG V2.0").
void requireBagStructure(const std::string& path);

}  // namespace cvg_bench
