#include "world/vdb_import.h"

#include <cmath>
#include <fstream>
#include <iterator>
#include <mutex>
#include <sstream>
#include <string>

#include <openvdb/io/Stream.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/GridTransformer.h>

#include "core/error.h"
#include "core/printable.h"
#include "core/read_file.h"
#include "world/color_pack.h"
#include "world/level_set_bricks.h"
#include "world/vdb_preflight.h"

namespace sdfstream {
namespace {

void initializeOpenVdb() {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
}

}  // namespace

// Linear, axis-aligned, uniform positive scale (+ translation): honoured without resampling.
bool isUniformAxisAligned(const openvdb::math::Transform& xf) {
  if (!xf.isLinear()) return false;
  const openvdb::Mat4d m = xf.baseMap()->getAffineMap()->getMat4();
  const double s = m(0, 0);
  if (!(s > 0.0) || !std::isfinite(s)) return false;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (std::abs(m(i, j) - (i == j ? s : 0.0)) > 1e-9 * s) return false;
  return true;
}

namespace {

// An unlabelled float grid that is a level set in all but name (see vdb_import.h).
bool looksLikeLevelSet(const openvdb::FloatGrid& grid) {
  if (!(grid.background() > 0.0f) || !isUniformAxisAligned(grid.transform())) return false;
  for (auto it = grid.cbeginValueOn(); it; ++it)
    if (*it < 0.0f) return true;
  return false;
}

std::string describe(const openvdb::GridBase& grid) {
  return describeVdbGrid(grid.getName(), openvdb::GridBase::gridClassToString(grid.getGridClass()),
                         grid.valueType());
}

// What a skipped float grid is, for the one-line note of readLevelSetGrids: "fog volume".
std::string kindOf(const openvdb::GridBase& grid) {
  if (grid.getGridClass() == openvdb::GRID_UNKNOWN) return "float grid, not a level set";
  return vdbGridKind(openvdb::GridBase::gridClassToString(grid.getGridClass()), grid.valueType());
}

}  // namespace

LevelSetFile readLevelSetGrids(const std::filesystem::path& path) {
  const std::string file = path.string();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw InputError(InputErrorKind::Io, file, "cannot open: no such file");
  initializeOpenVdb();

  // OpenVDB allocates and loops over whatever lengths the file declares: the preflight checks
  // them all first (vdb_preflight.h), and OpenVDB reads only the float grids it vouched for.
  VdbPreflight checked = preflightVdb(readWholeFile(path, file), file);
  LevelSetFile out;
  std::vector<std::string> holds(checked.order.size());
  try {
    openvdb::GridPtrVecPtr grids;
    if (checked.floatGridCount() > 0) {
      // io::Stream rather than io::File: OpenVDB's readers do not all check for the end of the
      // input; after reading every grid the stream must not have failed.
      std::istringstream in(std::move(checked.floatGridBytes), std::ios::binary);
      openvdb::io::Stream vdb(in, /*delayLoad=*/false);
      grids = vdb.getGrids();
      if (!in || !grids || grids->size() != checked.floatGridCount())
        throw InputError(InputErrorKind::Truncated, file, "file ends before its last grid");
    }
    std::size_t next = 0;
    for (std::size_t i = 0; i < checked.order.size(); ++i) {
      if (checked.order[i] >= 0) {
        const VdbOtherGrid& other = checked.others[std::size_t(checked.order[i])];
        holds[i] = other.description;
        out.skipped.push_back(other.name + " (" + other.kind + ")");
        continue;
      }
      const openvdb::GridBase::Ptr& g = (*grids)[next++];
      auto f = openvdb::gridPtrCast<openvdb::FloatGrid>(g);
      const bool labelled = f && f->getGridClass() == openvdb::GRID_LEVEL_SET;
      if (labelled || (f && f->getGridClass() == openvdb::GRID_UNKNOWN && looksLikeLevelSet(*f))) {
        out.grids.push_back(f);
        out.labelled.push_back(labelled);
        continue;
      }
      holds[i] = describe(*g);
      out.skipped.push_back("'" + printable(g->getName()) + "' (" + kindOf(*g) + ")");
    }
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {  // openvdb::Exception (IoError, ...) and std exceptions
    throw InputError(InputErrorKind::Truncated, file,
                     "truncated or corrupt .vdb: " + printable(e.what()));
  }
  if (out.grids.empty()) {
    std::string list;
    for (const std::string& h : holds)
      if (!h.empty()) list += (list.empty() ? "" : ", ") + h;
    throw InputError(
        InputErrorKind::NotLevelSet, file,
        "holds " + (list.empty() ? std::string("no grids") : list) + ", no float level set");
  }
  return out;
}

openvdb::FloatGrid::Ptr readLevelSetFile(const std::filesystem::path& path) {
  // The first labelled level set; failing that, the first unlabelled one (vdb_import.h).
  LevelSetFile f = readLevelSetGrids(path);
  for (std::size_t i = 0; i < f.grids.size(); ++i)
    if (f.labelled[i]) return f.grids[i];
  return f.grids.front();
}

World vdbToWorld(const std::filesystem::path& path, double voxelSizeOverride,
                 const ImportLimits& limits) {
  const std::string file = path.string();
  if (!(voxelSizeOverride >= 0.0) || !std::isfinite(voxelSizeOverride))
    throw InputError(InputErrorKind::OutOfRange, file, "voxel size must be positive (or 0)");
  openvdb::FloatGrid::Ptr grid = readLevelSetFile(path);

  const bool keep = voxelSizeOverride == 0.0 && isUniformAxisAligned(grid->transform());
  const double voxelSize = voxelSizeOverride > 0.0 ? voxelSizeOverride : grid->voxelSize()[0];
  if (!(voxelSize > 0.0) || !std::isfinite(voxelSize))
    throw InputError(InputErrorKind::Truncated, file, "corrupt transform: bad voxel size");
  // A surface's band scales with the square of the resolution change.
  const double ratio = grid->voxelSize()[0] / voxelSize;
  const double estimate = double(grid->activeVoxelCount()) * ratio * ratio * kBytesPerBandVoxel;
  if (estimate > double(limits.maxBytes))
    throw InputError(InputErrorKind::TooLarge, file,
                     "voxel size " + std::to_string(voxelSize) + " m needs about " +
                         std::to_string(estimate / double(1ull << 30)) + " GiB (limit " +
                         std::to_string(double(limits.maxBytes) / double(1ull << 30)) + " GiB)");

  if (!keep) {
    // Rebuild onto an axis-aligned grid; the output background sets the rebuilt half-width.
    auto out = openvdb::FloatGrid::create(float(layout::kNarrowBand * voxelSize));
    out->setTransform(openvdb::math::Transform::createLinearTransform(voxelSize));
    out->setGridClass(openvdb::GRID_LEVEL_SET);
    try {
      grid->setGridClass(openvdb::GRID_LEVEL_SET);  // unlabelled fallback grids too
      openvdb::tools::resampleToMatch<openvdb::tools::BoxSampler>(*grid, *out);
    } catch (const std::exception& e) {
      throw InputError(InputErrorKind::Malformed, file,
                       "cannot resample level set: " + printable(e.what()));
    }
    grid = out;
  }

  const std::uint32_t grey = packAlbedo(glm::vec4(0.8f, 0.8f, 0.8f, 1.0f));
  World world = bricksFromLevelSet(*grid, [grey](Brick& brick) {
    brick.albedo.fill(grey);
    brick.emission.fill(0u);
  });
  world.source = path.filename().string();
  if (world.bricks.empty())
    throw InputError(InputErrorKind::Empty, file, "level set has no voxel near its surface");
  return world;
}

}  // namespace sdfstream
