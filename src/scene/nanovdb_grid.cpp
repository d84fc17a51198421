#include "scene/nanovdb_grid.h"

#include <blosc.h>
#include <nanovdb/NanoVDB.h>
#include <nanovdb/util/IO.h>  // the file's Header and MetaData layout
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <stdexcept>
#include <type_traits>

namespace tessera {

namespace {

using FloatTree = nanovdb::NanoTree<float>;
using Leaf = nanovdb::NanoLeaf<float>;
using Lower = nanovdb::NanoLower<float>;
using Upper = nanovdb::NanoUpper<float>;

std::string grid_type_name(nanovdb::GridType t) {
  switch (t) {
    case nanovdb::GridType::Float: return "float";
    case nanovdb::GridType::Double: return "double";
    case nanovdb::GridType::Half: return "half";
    case nanovdb::GridType::Fp4: return "Fp4";
    case nanovdb::GridType::Fp8: return "Fp8";
    case nanovdb::GridType::Fp16: return "Fp16";
    case nanovdb::GridType::FpN: return "FpN";
    case nanovdb::GridType::Vec3f: return "Vec3f";
    default: return "type " + std::to_string(static_cast<int>(t));
  }
}

// A block of `dim`^3 voxels at `origin` holding one value.
struct Tile {
  nanovdb::Coord origin;
  int32_t dim;
  float value;
};

// The grid `name` of an .nvdb file, or an empty handle. NanoVDB's own
// readGrid trusts the file's sizes (a damaged name length reads past its
// buffer; a damaged grid size allocates whatever it says), so the container
// (segments of a header, per-grid metadata and names, then the grids, raw,
// zlib or Blosc) is read here, every size checked against what is left of
// the file before it is used.
nanovdb::GridHandle<nanovdb::HostBuffer> read_grid_bytes(const std::string& path, const std::string& name) {
  std::error_code ec;
  const uint64_t file_size = std::filesystem::file_size(path, ec);
  std::ifstream in(path, std::ios::binary);
  if (ec || !in) throw std::runtime_error("cannot open \"" + path + "\"");
  uint64_t pos = 0;
  auto fail = [&](const std::string& what) -> void { throw std::runtime_error(path + ": " + what); };
  auto read = [&](void* dst, uint64_t n, const char* what) {
    if (n > file_size - pos) fail(std::string("truncated (") + what + ")");
    in.read(static_cast<char*>(dst), static_cast<std::streamsize>(n));
    if (!in) fail(std::string("unreadable (") + what + ")");
    pos += n;
  };
  while (pos < file_size) {
    nanovdb::io::Header header;
    read(&header, sizeof header, "segment header");
    if (header.magic != NANOVDB_MAGIC_NUMBER) fail("not a NanoVDB file (bad magic number)");
    if (header.version.getMajor() != NANOVDB_MAJOR_VERSION_NUMBER)
      fail("written by NanoVDB " + std::to_string(header.version.getMajor()) + ".x; this build reads " +
           std::to_string(NANOVDB_MAJOR_VERSION_NUMBER) + ".x files (convert it with nanovdb_convert of that version)");
    const auto codec = header.codec;
    if (codec != nanovdb::io::Codec::NONE && codec != nanovdb::io::Codec::ZIP && codec != nanovdb::io::Codec::BLOSC)
      fail("unknown compression codec " + std::to_string(static_cast<int>(codec)));
    if (header.gridCount == 0) fail("a segment without grids");
    std::vector<nanovdb::io::MetaData> metas(header.gridCount);
    std::vector<std::string> names(header.gridCount);
    for (uint16_t i = 0; i < header.gridCount; ++i) {
      read(&metas[i], sizeof(nanovdb::io::MetaData), "grid metadata");
      const uint32_t n = metas[i].nameSize;
      if (n == 0 || n > 4096) fail("a grid name of " + std::to_string(n) + " bytes");
      std::string bytes(n, '\0');
      read(bytes.data(), n, "grid name");
      if (bytes.back() != '\0') fail("a grid name without its terminating zero");
      names[i] = bytes.c_str();
    }
    for (uint16_t i = 0; i < header.gridCount; ++i) {
      const nanovdb::io::MetaData& m = metas[i];
      if (m.fileSize > file_size - pos) fail("truncated (grid \"" + names[i] + "\")");
      if (names[i] != name) {
        in.seekg(static_cast<std::streamoff>(m.fileSize), std::ios_base::cur);
        pos += m.fileSize;
        continue;
      }
      // A grid is at least its header, and compressed data expands by a bounded factor (zlib: 1032).
      if (m.gridSize < sizeof(nanovdb::GridData) ||
          (codec == nanovdb::io::Codec::NONE ? m.gridSize != m.fileSize : m.gridSize / 1100 > m.fileSize))
        fail("grid \"" + name + "\" declares " + std::to_string(m.gridSize) + " bytes in " +
             std::to_string(m.fileSize) + " bytes of file");
      nanovdb::HostBuffer buffer = nanovdb::HostBuffer::create(m.gridSize);
      char* data = reinterpret_cast<char*>(buffer.data());
      const uint64_t end = pos + m.fileSize;
      if (codec == nanovdb::io::Codec::NONE) {
        read(data, m.gridSize, "grid data");
      } else if (codec == nanovdb::io::Codec::ZIP) {
        uint64_t size = 0;
        read(&size, sizeof size, "compressed size");
        if (size > end - pos) fail("truncated (compressed grid \"" + name + "\")");
        std::vector<Bytef> packed(size);
        read(packed.data(), size, "compressed grid");
        uLongf out = static_cast<uLongf>(m.gridSize);
        if (uncompress(reinterpret_cast<Bytef*>(data), &out, packed.data(), static_cast<uLong>(size)) != Z_OK ||
            out != m.gridSize)
          fail("grid \"" + name + "\" does not decompress (zlib)");
      } else {
        uint64_t done = 0;
        while (done < m.gridSize) {
          uint64_t size = 0;
          read(&size, sizeof size, "compressed size");
          if (size > end - pos) fail("truncated (compressed grid \"" + name + "\")");
          std::vector<char> packed(size);
          read(packed.data(), size, "compressed grid");
          const uint64_t chunk = std::min<uint64_t>(m.gridSize - done, uint64_t{1} << 30);
          size_t claimed = 0;
          if (blosc_cbuffer_validate(packed.data(), size, &claimed) != 0 || claimed != chunk ||
              blosc_decompress_ctx(packed.data(), data + done, chunk, 1) != static_cast<int>(chunk))
            fail("grid \"" + name + "\" does not decompress (Blosc)");
          done += chunk;
        }
      }
      return nanovdb::GridHandle<nanovdb::HostBuffer>(std::move(buffer));
    }
  }
  return {};
}

// Whether the grid's node arrays, as its tree header declares them, lie
// inside the buffer that was read. The reader below walks those arrays in
// order and follows no child pointer, so this is all it needs to stay in
// bounds on a damaged file. (NanoVDB's own validator follows the pointers
// and, on some damaged files, loops for ever: it is not used.)
bool layout_fits(const nanovdb::GridHandle<nanovdb::HostBuffer>& handle) {
  const uint64_t size = handle.size();
  const uint8_t* base = handle.data();
  using Grid = nanovdb::NanoGrid<float>;
  if (size < sizeof(nanovdb::GridData) + FloatTree::memUsage()) return false;
  const Grid* grid = reinterpret_cast<const Grid*>(base);
  if (grid->gridSize() > size) return false;
  const FloatTree& tree = grid->tree();
  const uint64_t tree_at = static_cast<uint64_t>(reinterpret_cast<const uint8_t*>(&tree) - base);
  if (tree_at + FloatTree::memUsage() > size) return false;
  const auto& t = *tree.data();
  auto fits = [&](uint64_t offset, uint64_t bytes) {
    return offset <= size && tree_at + offset <= size && bytes <= size - tree_at - offset &&
           (tree_at + offset) % NANOVDB_DATA_ALIGNMENT == 0;
  };
  const uint64_t node_bytes[3] = {sizeof(Leaf), sizeof(Lower), sizeof(Upper)};
  for (int level = 0; level < 3; ++level)
    if (t.mNodeCount[level] > 0 && !fits(t.mNodeOffset[level], t.mNodeCount[level] * node_bytes[level])) return false;
  using Root = nanovdb::NanoRoot<float>;
  if (!fits(t.mNodeOffset[3], sizeof(Root))) return false;
  const Root& root = tree.root();
  return fits(t.mNodeOffset[3], sizeof(Root) + uint64_t{root.tileCount()} * sizeof(typename Root::Tile));
}

}  // namespace

NanoVdbGrid read_nanovdb_grid(const std::string& path, const std::string& name, bool density) {
  NanoVdbGrid out;
  nanovdb::GridHandle<nanovdb::HostBuffer> handle;
  try {
    handle = read_grid_bytes(path, name);
  } catch (const std::bad_alloc&) {
    throw std::runtime_error(path + ": grid \"" + name + "\" does not fit in memory");
  }
  if (!handle) return out;
  // The handle's own accessors walk a multi-grid buffer by its headers'
  // sizes: the grid is taken directly, its header checked first.
  if (handle.size() < sizeof(nanovdb::GridData))
    throw std::runtime_error(path + ": grid \"" + name + "\" is damaged (shorter than its header)");
  const auto* grid = reinterpret_cast<const nanovdb::NanoGrid<float>*>(handle.data());
  if (!grid->isValid() || grid->version().getMajor() != NANOVDB_MAJOR_VERSION_NUMBER)
    throw std::runtime_error(path + ": grid \"" + name + "\" is damaged (bad grid header)");
  if (!grid->isFogVolume() && !grid->isUnknown())
    throw std::runtime_error(path + ": grid \"" + name + "\" is not a fog volume (pbrt-v4's nanovdb medium needs one)");
  if (grid->gridType() != nanovdb::GridType::Float)
    throw std::runtime_error(path + ": grid \"" + name + "\" holds " + grid_type_name(grid->gridType()) +
                             " values; only float grids are supported (as in pbrt-v4)");
  if (!layout_fits(handle))
    throw std::runtime_error(path + ": grid \"" + name + "\" is damaged (its nodes lie outside the data read)");

  // A density is finite and not negative, with no density outside the grid;
  // a temperature only finite (its background is what lies outside).
  const FloatTree& tree = grid->tree();
  const float background = tree.root().background();
  auto check = [&](float v) {
    if (!std::isfinite(v) || (density && v < 0.f))
      throw std::runtime_error(path + ": grid \"" + name + "\" holds a " + (density ? "negative or " : "") +
                               "non-finite value");
  };
  check(background);
  if (density && background != 0.f)
    throw std::runtime_error(path + ": grid \"" + name + "\" has a non-zero background density");
  for (auto it = tree.root().beginValue(); it; ++it)
    if (*it != background)
      throw std::runtime_error(path + ": grid \"" + name + "\" has a root tile (4096^3 voxels) unlike its background");

  // Leaves, and the internal nodes' constant tiles unlike the background.
  std::vector<Tile> tiles;
  const uint32_t uppers = tree.nodeCount(2), lowers = tree.nodeCount(1), leaves = tree.nodeCount(0);
  auto node_tiles = [&](const auto* node, int32_t child_dim) {
    using Node = std::remove_pointer_t<decltype(node)>;
    for (uint32_t n = 0; n < Node::SIZE; ++n) {
      if (node->childMask().isOn(n)) continue;
      const float v = node->data()->getValue(n);
      if (v != background) tiles.push_back({node->offsetToGlobalCoord(n), child_dim, v});
    }
  };
  for (uint32_t i = 0; i < uppers; ++i) node_tiles(tree.getFirstUpper() + i, static_cast<int32_t>(Lower::DIM));
  for (uint32_t i = 0; i < lowers; ++i) node_tiles(tree.getFirstLower() + i, static_cast<int32_t>(Leaf::DIM));
  const Leaf* first_leaf = tree.getFirstLeaf();

  // The lattice spans every leaf and tile, from a multiple of 8 so that leaves are bricks.
  int64_t lo[3], hi[3];  // inclusive voxel range
  for (int a = 0; a < 3; ++a) {
    lo[a] = std::numeric_limits<int64_t>::max();
    hi[a] = std::numeric_limits<int64_t>::min();
  }
  auto cover = [&](const nanovdb::Coord& o, int32_t dim) {
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min<int64_t>(lo[a], o[a]);
      hi[a] = std::max<int64_t>(hi[a], static_cast<int64_t>(o[a]) + dim - 1);
    }
  };
  for (uint32_t i = 0; i < leaves; ++i) cover((first_leaf + i)->origin(), static_cast<int32_t>(Leaf::dim()));
  for (const Tile& t : tiles) cover(t.origin, t.dim);
  int64_t shift[3] = {0, 0, 0}, n[3] = {1, 1, 1};
  if (leaves > 0 || !tiles.empty()) {
    for (int a = 0; a < 3; ++a) {
      shift[a] = static_cast<int64_t>(std::floor(lo[a] / static_cast<double>(kBrickSide))) * kBrickSide;
      n[a] = hi[a] - shift[a] + 1;
      // Lattice coordinates are float in the kernels: exact integers up to 2^24.
      if (n[a] > (int64_t{1} << 24))
        throw std::runtime_error(path + ": grid \"" + name + "\" spans more than 2^24 voxels along an axis");
    }
  }
  // The brick index has an entry per 8^3 voxels of the box around the
  // grid: 2^27 of them (512 MB, a box of 4096^3 voxels) is the most we take.
  const uint64_t bricks = static_cast<uint64_t>((n[0] + 7) / 8) * ((n[1] + 7) / 8) * ((n[2] + 7) / 8);
  if (bricks > (uint64_t{1} << 27))
    throw std::runtime_error(path + ": grid \"" + name + "\" spans " + std::to_string(n[0]) + " x " +
                             std::to_string(n[1]) + " x " + std::to_string(n[2]) +
                             " voxels; at most 4096^3 voxels' worth are supported");

  SparseGridBuilder b(static_cast<int32_t>(n[0]), static_cast<int32_t>(n[1]), static_cast<int32_t>(n[2]), background);
  // Tiles (aligned to their 8^3 or 128^3 size, so to bricks) share one brick per value.
  for (const Tile& t : tiles) {
    check(t.value);
    const int32_t bricks_per_side = t.dim / kBrickSide;
    int32_t first[3];
    for (int a = 0; a < 3; ++a) first[a] = static_cast<int32_t>((t.origin[a] - shift[a]) / kBrickSide);
    for (int32_t z = 0; z < bricks_per_side; ++z)
      for (int32_t y = 0; y < bricks_per_side; ++y)
        for (int32_t x = 0; x < bricks_per_side; ++x) b.fill_brick(first[0] + x, first[1] + y, first[2] + z, t.value);
  }
  for (uint32_t i = 0; i < leaves; ++i) {
    const Leaf* leaf = first_leaf + i;
    const nanovdb::Coord o = leaf->origin();
    for (uint32_t k = 0; k < Leaf::voxelCount(); ++k) {
      const float v = leaf->getValue(k);
      check(v);
      const nanovdb::Coord c = Leaf::OffsetToLocalCoord(k);
      b.set(static_cast<int32_t>(o[0] + c[0] - shift[0]), static_cast<int32_t>(o[1] + c[1] - shift[1]),
            static_cast<int32_t>(o[2] + c[2] - shift[2]), v);
    }
  }

  // world -> index is affine (NanoVDB's map): read it off at the origin and the unit vectors.
  const nanovdb::Vec3d i0 = grid->worldToIndex(nanovdb::Vec3d(0.0, 0.0, 0.0));
  Mat4 lattice_from_world(1.f);
  for (int a = 0; a < 3; ++a) {
    nanovdb::Vec3d e(0.0, 0.0, 0.0);
    e[a] = 1.0;
    const nanovdb::Vec3d ia = grid->worldToIndex(e);
    for (int r = 0; r < 3; ++r) lattice_from_world[a][r] = static_cast<Float>(ia[r] - i0[r]);
  }
  for (int r = 0; r < 3; ++r) lattice_from_world[3][r] = static_cast<Float>(i0[r] - static_cast<double>(shift[r]));
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 3; ++r)
      if (!std::isfinite(lattice_from_world[c][r]))
        throw std::runtime_error(path + ": grid \"" + name + "\" has a non-finite or singular transform");
  out.lattice = b.finish(lattice_from_world);
  const auto& wb = grid->worldBBox();
  out.world_lo = Vec3(static_cast<Float>(wb.min()[0]), static_cast<Float>(wb.min()[1]), static_cast<Float>(wb.min()[2]));
  out.world_hi = Vec3(static_cast<Float>(wb.max()[0]), static_cast<Float>(wb.max()[1]), static_cast<Float>(wb.max()[2]));
  if (!is_finite(out.world_lo) || !is_finite(out.world_hi)) {
    // NanoVDB's bounding box of a grid with no active voxel is empty (+-DBL_MAX).
    if (leaves > 0 || !tiles.empty())
      throw std::runtime_error(path + ": grid \"" + name + "\" has a non-finite bounding box");
    out.world_lo = out.world_hi = Vec3(0.f);
  }
  out.found = true;
  return out;
}

}  // namespace tessera
