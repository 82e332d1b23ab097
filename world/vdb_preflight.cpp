#include "world/vdb_preflight.h"

#include <array>
#include <bit>
#include <cstdint>
#include <cstring>
#include <map>
#include <string_view>

#include <openvdb/io/DelayedLoadMetadata.h>
#include <openvdb/io/GridDescriptor.h>
#include <openvdb/openvdb.h>

#include "core/error.h"
#include "core/printable.h"

namespace sdfstream {
namespace {

// The file format versions whose layout this walk follows: 222 added per-grid compression and
// per-node metadata bytes (NODE_MASK_COMPRESSION), 224 is what OpenVDB 10 writes.
constexpr std::uint32_t kFirstVersion = 222;
constexpr std::uint32_t kLastVersion = 224;
static_assert(openvdb::OPENVDB_FILE_VERSION == kLastVersion,
              "a newer OpenVDB file format: check the walk below against its readers");

// io/Compression.h: the grid's compression flags and the per-node metadata byte.
constexpr std::uint32_t kCompressZip = 0x1;
constexpr std::uint32_t kCompressActiveMask = 0x2;
constexpr std::uint32_t kCompressBlosc = 0x4;
enum NodeMetadata : std::uint8_t {
  kNoMaskAndOneInactiveVal = 2,
  kMaskAndNoInactiveVals = 3,
  kMaskAndOneInactiveVal = 4,
  kMaskAndTwoInactiveVals = 5,
  kNoMaskAndAllVals = 6,
};

constexpr std::string_view kHalfFloatSuffix = "_HalfFloat";  // io/GridDescriptor.cc
constexpr std::size_t kBloscHeaderBytes = 16;

// Byte sizes of the transforms' bodies (math/Maps.h read()): Vec3d = 24, Mat4d = 128 bytes.
std::size_t linearMapBytes(const std::string& type) {
  if (type == "AffineMap" || type == "UnitaryMap") return 128;
  if (type == "ScaleMap" || type == "UniformScaleMap") return 5 * 24;
  if (type == "ScaleTranslateMap" || type == "UniformScaleTranslateMap") return 6 * 24;
  if (type == "TranslationMap") return 24;
  return 0;
}

class Cursor {
 public:
  Cursor(const std::string& bytes, const std::string& file) : bytes_(bytes), file_(file) {}

  std::size_t pos() const { return pos_; }
  std::size_t left() const { return end_ - pos_; }
  const char* here() const { return bytes_.data() + pos_; }
  void seek(std::size_t pos) { pos_ = pos; }
  // Reads stay within [pos, end): a grid's bytes end where its descriptor says.
  void limitTo(std::size_t end) { end_ = end; }
  void unlimit() { end_ = bytes_.size(); }
  // Prefix of every message while one grid is walked ("grid 'name': ").
  void setContext(std::string context) { context_ = std::move(context); }

  void need(std::uint64_t n, const std::string& what) const {
    if (n > left())
      fail(InputErrorKind::Truncated, what + " needs " + std::to_string(n) + " bytes at byte " +
                                          std::to_string(pos_) + ", " + std::to_string(left()) +
                                          " are left");
  }
  void skip(std::uint64_t n, const std::string& what) {
    need(n, what);
    pos_ += static_cast<std::size_t>(n);
  }
  template <typename T>
  T get(const std::string& what) {
    need(sizeof(T), what);
    T v;
    std::memcpy(&v, here(), sizeof(T));
    pos_ += sizeof(T);
    return v;
  }
  // io::readString: a uint32 length, then the bytes.
  std::string string(const std::string& what) {
    const auto n = get<std::uint32_t>(what + "'s length");
    need(n, what);
    std::string s = bytes_.substr(pos_, n);
    pos_ += n;
    return s;
  }
  [[noreturn]] void fail(InputErrorKind kind, const std::string& problem) const {
    throw InputError(kind, file_, "truncated or corrupt .vdb: " + context_ + problem);
  }

 private:
  const std::string& bytes_;
  const std::string& file_;
  std::size_t pos_ = 0;
  std::size_t end_ = bytes_.size();
  std::string context_;
};

std::size_t countOn(const char* mask, std::size_t bytes) {
  std::size_t n = 0;
  for (std::size_t i = 0; i < bytes; ++i) n += std::popcount(static_cast<unsigned char>(mask[i]));
  return n;
}

// MetaMap::readMeta. Entries are kept as byte spans so the map can be written out again without
// OpenVDB's delayed-load entry, whose reader allocates counts it reads from inside the value.
struct MetaWalk {
  std::string kept;  // the entries OpenVDB may read, back to back
  std::uint32_t keptCount = 0;
  std::string gridName, gridClass;  // the "name" and "class" strings, when present

  std::string serialized() const {
    std::string out(sizeof keptCount, '\0');
    std::memcpy(out.data(), &keptCount, sizeof keptCount);
    return out + kept;
  }
};

// The metadata OpenVDB itself reads or writes by name (GridBase::META_*): an entry of another
// type under such a name makes OpenVDB throw later, outside any read (setGridClass of a grid
// whose "class" is an int64, found by fuzzing).
const char* reservedMetaType(const std::string& name) {
  using namespace openvdb;
  if (name == GridBase::META_GRID_CLASS || name == GridBase::META_GRID_NAME ||
      name == GridBase::META_GRID_CREATOR || name == GridBase::META_VECTOR_TYPE ||
      name == GridBase::META_FILE_COMPRESSION)
    return "string";
  if (name == GridBase::META_SAVE_HALF_FLOAT || name == GridBase::META_IS_LOCAL_SPACE)
    return "bool";
  if (name == GridBase::META_FILE_BBOX_MIN || name == GridBase::META_FILE_BBOX_MAX) return "vec3i";
  if (name == GridBase::META_FILE_MEM_BYTES || name == GridBase::META_FILE_VOXEL_COUNT)
    return "int64";
  if (name == GridBase::META_FILE_DELAYED_LOAD) return "__delayedload";
  return nullptr;
}

MetaWalk walkMeta(Cursor& c, const std::string& bytes, const std::string& what) {
  MetaWalk walk;
  const auto count = c.get<std::uint32_t>(what + " count");
  // An entry is at least two string lengths and a value size: a larger count is a lie, and
  // OpenVDB would loop over it reading past the end.
  c.need(std::uint64_t(count) * 12, what + " (" + std::to_string(count) + " entries)");
  for (std::uint32_t i = 0; i < count; ++i) {
    const std::size_t begin = c.pos();
    const std::string name = c.string(what + " name");
    const std::string entry = what + " '" + printable(name) + "'";
    const std::string type = c.string(entry + " type name");
    if (const char* expected = reservedMetaType(name); expected && type != expected)
      c.fail(InputErrorKind::Malformed, entry + " has type '" + printable(type) +
                                            "' where OpenVDB expects " + expected);
    const auto size = c.get<std::uint32_t>(entry + " value size");
    c.need(size, entry + " value");
    if (type == openvdb::io::DelayedLoadMetadata::staticTypeName()) {
      c.skip(size, entry);
      continue;
    }
    if (type != "string" && openvdb::Metadata::isRegisteredType(type)) {
      // OpenVDB reads a fixed-size value by its type's size, whatever size the file states.
      const std::size_t expected = openvdb::Metadata::createMetadata(type)->size();
      if (size != expected)
        c.fail(InputErrorKind::Malformed, entry + " of type " + printable(type) + " holds " +
                                              std::to_string(size) + " bytes, the type has " +
                                              std::to_string(expected));
    }
    if (type == "string" && name == "name") walk.gridName.assign(c.here(), size);
    if (type == "string" && name == "class") walk.gridClass.assign(c.here(), size);
    c.skip(size, entry);
    walk.kept.append(bytes, begin, c.pos() - begin);
    ++walk.keptCount;
  }
  return walk;
}

// math::Transform::read for format versions >= 219: a map type name, then its body.
void walkTransform(Cursor& c) {
  const std::string type = c.string("transform type name");
  if (type == "NonlinearFrustumMap") {
    c.skip(48 + 8 + 8, "frustum bounds, taper and depth");  // BBoxd, two doubles
    const std::string second = c.string("frustum's linear map type name");
    const std::size_t bytes = linearMapBytes(second);
    if (bytes == 0)
      c.fail(InputErrorKind::Malformed,
             "the frustum's linear map type '" + printable(second) + "' is not one OpenVDB reads");
    c.skip(bytes, "frustum's linear map");
    return;
  }
  const std::size_t bytes = linearMapBytes(type);
  if (bytes == 0)
    c.fail(InputErrorKind::Malformed,
           "transform type '" + printable(type) + "' is not one OpenVDB reads");
  c.skip(bytes, "transform");
}

// A float tree (Tree_float_5_4_3): tree/Tree.h, RootNode.h, InternalNode.h, LeafNode.h and
// io/Compression.h (readCompressedValues, readData, bloscFromStream, unzipFromStream).
class FloatTreeWalk {
 public:
  FloatTreeWalk(Cursor& c, std::uint32_t compression, bool half)
      : c_(c), compression_(compression), half_(half) {}

  // Returns the position where the topology ends (the grid's block position) after walking
  // topology and buffers.
  std::size_t walk() {
    c_.skip(4, "tree buffer count");
    c_.skip(4, "background value");
    const auto numTiles = c_.get<std::uint32_t>("root tile count");
    const auto numChildren = c_.get<std::uint32_t>("root child count");
    if (numTiles == 0 && numChildren == 0) return c_.pos();  // an empty tree has no buffers
    c_.skip(std::uint64_t(numTiles) * (12 + 4 + 1), "root tiles");  // origin, value, active
    // A child holds at least its origin, two 4096-byte masks and a metadata byte.
    c_.need(std::uint64_t(numChildren) * (12 + 2 * 4096 + 1),
            "root children (" + std::to_string(numChildren) + ")");
    // RootNode::readTopology keys children by their stored origin, a later child replacing an
    // earlier one; readBuffers then visits only the children that stayed.
    std::map<std::array<std::int32_t, 3>, std::uint64_t> leavesByChild;
    for (std::uint32_t i = 0; i < numChildren; ++i) {
      std::array<std::int32_t, 3> origin;
      for (std::int32_t& v : origin) v = c_.get<std::int32_t>("root child origin");
      leavesByChild[origin] = internalNode(5);
    }
    const std::size_t topologyEnd = c_.pos();
    std::uint64_t leaves = 0;
    for (const auto& [origin, n] : leavesByChild) leaves += n;
    // Every leaf buffer holds at least its 64-byte value mask and a metadata byte.
    c_.need(leaves * 65, "leaf buffers (" + std::to_string(leaves) + " leaves)");
    for (std::uint64_t i = 0; i < leaves; ++i) {
      c_.need(64, "leaf value mask");
      const std::size_t active = countOn(c_.here(), 64);
      c_.skip(64, "leaf value mask");
      values(512, active, "leaf values");
    }
    return topologyEnd;
  }

 private:
  // InternalNode<…, log2Dim>::readTopology; returns the number of leaves below.
  std::uint64_t internalNode(int log2Dim) {
    const std::size_t numValues = std::size_t(1) << (3 * log2Dim);
    const std::size_t maskBytes = numValues / 8;
    c_.need(2 * maskBytes, "node masks");
    const std::string childMask(c_.here(), maskBytes);
    const std::size_t active = countOn(c_.here() + maskBytes, maskBytes);
    c_.skip(2 * maskBytes, "node masks");
    values(numValues, active, "node values");
    std::uint64_t leaves = 0;
    for (std::size_t byte = 0; byte < maskBytes; ++byte) {
      for (int bit = 0; bit < 8; ++bit) {
        if (!(static_cast<unsigned char>(childMask[byte]) >> bit & 1)) continue;
        if (log2Dim == 4) {
          c_.skip(64, "leaf value mask");  // LeafNode::readTopology
          ++leaves;
        } else {
          leaves += internalNode(log2Dim - 1);
        }
      }
    }
    return leaves;
  }

  // io::readCompressedValues for a node of destCount values, activeCount of them active.
  void values(std::size_t destCount, std::size_t activeCount, const std::string& what) {
    const auto metadata = c_.get<std::uint8_t>(what + " metadata byte");
    if (metadata == kNoMaskAndOneInactiveVal || metadata == kMaskAndOneInactiveVal ||
        metadata == kMaskAndTwoInactiveVals)
      c_.skip(4, what + " inactive value");
    if (metadata == kMaskAndTwoInactiveVals) c_.skip(4, what + " second inactive value");
    if (metadata == kMaskAndNoInactiveVals || metadata == kMaskAndOneInactiveVal ||
        metadata == kMaskAndTwoInactiveVals)
      c_.skip(destCount / 8, what + " selection mask");
    const std::size_t count =
        (compression_ & kCompressActiveMask) && metadata != kNoMaskAndAllVals ? activeCount
                                                                               : destCount;
    if (half_ && count == 0) return;  // HalfReader reads nothing at all
    const std::uint64_t bytes = std::uint64_t(count) * (half_ ? 2 : 4);
    if (!(compression_ & (kCompressBlosc | kCompressZip))) {
      c_.skip(bytes, what);
      return;
    }
    const auto stored = c_.get<std::int64_t>(what + " chunk size");
    if (stored <= 0) {
      // An uncompressed chunk: OpenVDB reads it into the node's buffer before comparing lengths.
      const std::uint64_t raw = std::uint64_t(0) - static_cast<std::uint64_t>(stored);
      if (raw != bytes)
        c_.fail(InputErrorKind::Malformed, what + " hold an uncompressed chunk of " +
                                               std::to_string(raw) + " bytes where " +
                                               std::to_string(bytes) + " belong");
      c_.skip(raw, what);
      return;
    }
    const auto chunk = static_cast<std::uint64_t>(stored);
    c_.need(chunk, what + " compressed chunk");
    if (compression_ & kCompressBlosc) {
      // blosc_decompress_ctx trusts the sizes in the chunk's own header, not OpenVDB's.
      std::uint32_t uncompressed = 0, compressed = 0;
      if (chunk >= kBloscHeaderBytes) {
        std::memcpy(&uncompressed, c_.here() + 4, 4);
        std::memcpy(&compressed, c_.here() + 12, 4);
      }
      if (chunk < kBloscHeaderBytes || uncompressed != bytes || compressed > chunk)
        c_.fail(InputErrorKind::Malformed,
                what + " hold a blosc chunk whose header disagrees with its size (" +
                    std::to_string(chunk) + " bytes for " + std::to_string(bytes) + ")");
    }
    c_.skip(chunk, what);
  }

  Cursor& c_;
  std::uint32_t compression_;
  bool half_;
};

}  // namespace

std::string vdbGridKind(const std::string& gridClass, const std::string& valueType) {
  if (valueType.rfind("ptdataidx", 0) == 0) return "point data";
  if (!gridClass.empty() && gridClass != "unknown") return printable(gridClass);
  return printable(valueType) + " grid";
}

std::string describeVdbGrid(const std::string& name, const std::string& gridClass,
                            const std::string& valueType) {
  const std::string quoted = "'" + printable(name) + "'";
  if (valueType.rfind("ptdataidx", 0) == 0) return "point data " + quoted;
  const bool classless = gridClass.empty() || gridClass == "unknown";
  return (classless ? std::string("grid") : printable(gridClass)) + " " + quoted + " (" +
         printable(valueType) + ")";
}

VdbPreflight preflightVdb(const std::string& bytes, const std::string& file) {
  openvdb::initialize();
  Cursor c(bytes, file);
  VdbPreflight out;

  // io::Archive::readHeader.
  const auto magic = c.get<std::int64_t>("VDB magic number");
  if (magic != openvdb::OPENVDB_MAGIC)
    c.fail(InputErrorKind::Malformed, "not a .vdb file (no VDB magic number)");
  const auto version = c.get<std::uint32_t>("file format version");
  if (version < kFirstVersion || version > kLastVersion)
    throw InputError(InputErrorKind::Version, file,
                     ".vdb file format version " + std::to_string(version) +
                         "; sdfstream reads versions " + std::to_string(kFirstVersion) + " to " +
                         std::to_string(kLastVersion));
  c.skip(8, "library version");
  const bool hasGridOffsets = c.get<char>("grid offset flag") != 0;
  c.skip(36, "UUID");
  out.floatGridBytes.assign(bytes, 0, c.pos());

  c.setContext("file metadata: ");
  out.floatGridBytes += walkMeta(c, bytes, "metadata").serialized();
  c.setContext("");
  const auto gridCount = c.get<std::int32_t>("grid count");
  // A descriptor is at least three string lengths and three offsets.
  if (gridCount < 0) c.fail(InputErrorKind::Malformed, "negative grid count");
  c.need(std::uint64_t(gridCount) * 36, std::to_string(gridCount) + " grid descriptors");
  const std::size_t countAt = out.floatGridBytes.size();
  out.floatGridBytes.append(sizeof(std::int32_t), '\0');

  for (std::int32_t g = 0; g < gridCount; ++g) {
    // io::GridDescriptor::read, then Archive::readGrid.
    c.unlimit();
    c.setContext("grid " + std::to_string(g) + ": ");
    const std::size_t descriptorBegin = c.pos();
    const std::string uniqueName = c.string("grid name");
    const std::string storedType = c.string("grid type");
    const std::string parent = c.string("instance parent name");
    const auto gridPos = c.get<std::int64_t>("grid position");
    const auto blockPos = c.get<std::int64_t>("block position");
    const auto endPos = c.get<std::int64_t>("end position");
    const std::size_t descriptorEnd = c.pos();
    const std::string name = openvdb::io::GridDescriptor::stripSuffix(uniqueName);
    c.setContext("grid '" + printable(name) + "': ");

    const bool half = storedType.size() > kHalfFloatSuffix.size() &&
                      storedType.ends_with(kHalfFloatSuffix);
    const std::string type =
        half ? storedType.substr(0, storedType.size() - kHalfFloatSuffix.size()) : storedType;
    const bool isFloat = type == openvdb::FloatGrid::gridType();

    if (hasGridOffsets) {
      if (endPos < 0 || std::uint64_t(endPos) > bytes.size())
        c.fail(InputErrorKind::Truncated, "its data ends at byte " + std::to_string(endPos) +
                                              ", the file has " + std::to_string(bytes.size()));
      // An instance (a grid sharing a tree written before it) stores no buffers: block position 0.
      const bool blockOk = parent.empty() ? blockPos >= gridPos && endPos >= blockPos : true;
      if (gridPos != std::int64_t(descriptorEnd) || endPos < gridPos || !blockOk)
        c.fail(InputErrorKind::Malformed,
               "its descriptor places it at bytes " + std::to_string(gridPos) + ".." +
                   std::to_string(endPos) + " (buffers from " + std::to_string(blockPos) +
                   "), but it begins at byte " + std::to_string(descriptorEnd));
      c.limitTo(static_cast<std::size_t>(endPos));
    }
    const std::size_t compressionAt = c.pos();
    const auto compression = c.get<std::uint32_t>("compression flags");
    const std::size_t metaBegin = c.pos();
    const MetaWalk meta = walkMeta(c, bytes, "metadata");
    const std::size_t metaBytes = c.pos() - metaBegin;

    if (!isFloat) {
      if (!hasGridOffsets)
        throw InputError(InputErrorKind::Unsupported, file,
                         "grid '" + printable(name) + "' (" + printable(storedType) +
                             ") of a .vdb written as a stream, without grid offsets: only float "
                             "grids can be read from such a file");
      const std::string valueType = openvdb::GridBase::isRegistered(type)
                                        ? openvdb::GridBase::createGrid(type)->valueType()
                                        : type;
      const std::string shown = meta.gridName.empty() ? name : meta.gridName;
      out.order.push_back(static_cast<int>(out.others.size()));
      out.others.push_back({"'" + printable(shown) + "'", vdbGridKind(meta.gridClass, valueType),
                            describeVdbGrid(shown, meta.gridClass, valueType)});
      c.seek(static_cast<std::size_t>(endPos));
      continue;
    }

    const std::size_t transformBegin = c.pos();
    walkTransform(c);
    std::size_t topologyEnd = c.pos();
    if (parent.empty()) topologyEnd = FloatTreeWalk(c, compression, half).walk();
    const bool blockMatches = !parent.empty() || topologyEnd == std::size_t(blockPos);
    if (hasGridOffsets && (!blockMatches || c.pos() != std::size_t(endPos)))
      c.fail(InputErrorKind::Malformed,
             "its topology and buffers end at bytes " + std::to_string(topologyEnd) + " and " +
                 std::to_string(c.pos()) + ", its descriptor says " + std::to_string(blockPos) +
                 " and " + std::to_string(endPos));

    // The grid again, its offsets moved to where it now lies and without dropped metadata.
    const std::string rebuiltMeta = meta.serialized();
    std::string& o = out.floatGridBytes;
    o.append(bytes, descriptorBegin, descriptorEnd - 24 - descriptorBegin);
    std::int64_t offsets[3] = {0, 0, 0};
    if (hasGridOffsets) {
      const std::int64_t newGridPos = static_cast<std::int64_t>(o.size() + 24);
      const std::int64_t shift = newGridPos - gridPos + std::int64_t(rebuiltMeta.size()) -
                                 std::int64_t(metaBytes);
      offsets[0] = newGridPos;
      offsets[1] = parent.empty() ? blockPos + shift : blockPos;
      offsets[2] = endPos + shift;
    }
    o.append(reinterpret_cast<const char*>(offsets), sizeof offsets);
    o.append(bytes, compressionAt, metaBegin - compressionAt);
    o += rebuiltMeta;
    o.append(bytes, transformBegin, c.pos() - transformBegin);
    out.order.push_back(-1);
  }
  const auto kept = static_cast<std::int32_t>(out.floatGridCount());
  std::memcpy(out.floatGridBytes.data() + countAt, &kept, sizeof kept);
  return out;
}

}  // namespace sdfstream
