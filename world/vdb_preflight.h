// Checks every length a .vdb file declares against the bytes it holds, before OpenVDB reads it.
//
// OpenVDB's readers trust the file: they allocate what it declares before reading (a string's
// length, a compressed chunk's size, a metadata array's count, a reserve of the grid count), loop
// over declared node counts without checking for the end of the stream, and read an uncompressed
// chunk into a node's fixed buffer before comparing its length with the buffer's. Hostile bytes
// can therefore make them allocate gigabytes, spin, or overrun a leaf. The preflight walks the
// same structure (io/Archive, io/GridDescriptor, MetaMap, math/Transform, tree/RootNode,
// InternalNode, LeafNode and io/Compression of OpenVDB 10, file format versions 222-224) and
// bounds each of those lengths by the bytes left, so OpenVDB only ever sees a file whose every
// declared size is honest.
//
// Only float grids (the one type the importer uses, level sets and fog volumes alike) are walked
// to the last byte. Grids of any other type are described from the container (name, class, value
// type) and cut out of the bytes handed to OpenVDB, which never parses them.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace sdfstream {

// A grid the preflight cut out: its name as stored and what it is ("vec3s grid 'v'",
// "point data 'points'"), both already quoted printable for one-line errors.
struct VdbOtherGrid {
  std::string name;         // 'name'
  std::string kind;         // "point data", "fog volume", "vec3s grid", ...
  std::string description;  // kind + name (+ value type), as NotLevelSet names it
};

struct VdbPreflight {
  // The file with only its float grids (grid count adjusted, OpenVDB's delayed-load metadata
  // dropped: it only serves memory-mapped reads): what io::Stream may read.
  std::string floatGridBytes;
  // For each grid in file order: -1 when it is a float grid (read by OpenVDB, in the same order),
  // else its index in `others`.
  std::vector<int> order;
  std::vector<VdbOtherGrid> others;

  std::size_t floatGridCount() const { return order.size() - others.size(); }
};

// How errors name a grid: "fog volume 'density' (float)", "point data 'points'", "grid 'v'
// (vec3s)". gridClass as OpenVDB stores it in the grid's "class" metadata ("" or "unknown": none).
std::string describeVdbGrid(const std::string& name, const std::string& gridClass,
                            const std::string& valueType);
// What a skipped grid is, for a one-line note: "point data", "fog volume", "vec3s grid".
std::string vdbGridKind(const std::string& gridClass, const std::string& valueType);

// Throws InputError naming `file` and the first dishonest length: Truncated (a length runs past
// the end of the file or of its grid), Malformed (not a .vdb, an inconsistent size, an unknown
// transform of a float grid), Version (a file format other than 222-224), Unsupported (a
// non-float grid in a file written without grid offsets, which cannot be skipped).
VdbPreflight preflightVdb(const std::string& bytes, const std::string& file);

}  // namespace sdfstream
