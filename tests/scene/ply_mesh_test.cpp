// The PLY reader: every encoding pbrt-v4 reads gives the same mesh, and no
// input, however malformed, crashes, hangs or reads out of bounds.
#include <gtest/gtest.h>
#include <zlib.h>

#include <cstring>
#include <random>

#include "scene/ply_mesh.h"
#include "scene/scene_desc.h"
#include "scene_test_helpers.h"

namespace tessera {
namespace {

using test::load_error;
using test::load_world;
using test::TempDir;

// The case that aborted Assimp's triangulation: 5 vertices with normals and
// uv, three faces (two triangles and a quad).
struct SmallMesh {
  std::vector<float> p = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0.5f, 2, 0.25f};
  std::vector<float> n = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0.6f, 0.8f};
  std::vector<float> uv = {0, 0, 1, 0, 1, 1, 0, 1, 0.5f, 2};
  std::vector<std::vector<int>> faces = {{0, 1, 2}, {2, 3, 0}, {3, 2, 4, 0}};
};

enum class Encoding { Ascii, Little, Big };

std::string header(Encoding e, size_t vertices, size_t faces, const char* uv_names = "u v") {
  const char* format = e == Encoding::Ascii ? "ascii" : e == Encoding::Little ? "binary_little_endian" : "binary_big_endian";
  std::string u(uv_names, std::strchr(uv_names, ' ')), v(std::strchr(uv_names, ' ') + 1);
  return std::string("ply\nformat ") + format + " 1.0\ncomment made by the test\nelement vertex " +
         std::to_string(vertices) +
         "\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\n"
         "property float nz\nproperty float " + u + "\nproperty float " + v + "\nelement face " + std::to_string(faces) +
         "\nproperty list uchar int vertex_indices\nend_header\n";
}

template <typename T>
void put(std::string& out, T value, Encoding e) {
  char b[sizeof(T)];
  std::memcpy(b, &value, sizeof(T));
  if (e == Encoding::Big) std::reverse(b, b + sizeof(T));
  out.append(b, sizeof(T));
}

std::string write_ply(const SmallMesh& m, Encoding e, const char* uv_names = "u v") {
  const size_t nv = m.p.size() / 3;
  std::string out = header(e, nv, m.faces.size(), uv_names);
  for (size_t v = 0; v < nv; ++v) {
    const float values[8] = {m.p[3 * v], m.p[3 * v + 1], m.p[3 * v + 2], m.n[3 * v], m.n[3 * v + 1], m.n[3 * v + 2],
                             m.uv[2 * v], m.uv[2 * v + 1]};
    for (float x : values) {
      if (e == Encoding::Ascii) {
        out += std::to_string(x);
        out += &x == &values[7] ? '\n' : ' ';
      } else {
        put(out, x, e);
      }
    }
  }
  for (const auto& f : m.faces) {
    if (e == Encoding::Ascii) {
      out += std::to_string(f.size());
      for (int i : f) {
        out += ' ';
        out += std::to_string(i);
      }
      out += "\n";
    } else {
      put(out, static_cast<uint8_t>(f.size()), e);
      for (int i : f) put(out, static_cast<int32_t>(i), e);
    }
  }
  return out;
}

std::string gzip(const std::string& bytes, const std::string& path) {
  gzFile f = gzopen(path.c_str(), "wb");
  gzwrite(f, bytes.data(), static_cast<unsigned>(bytes.size()));
  gzclose(f);
  return path;
}

std::string parse_error(const std::string& bytes) {
  try {
    parse_ply_mesh(bytes, "m.ply");
  } catch (const SceneError& e) {
    return e.what();
  }
  return "";
}

void expect_small_mesh(const PlyMesh& got) {
  const SmallMesh m;
  ASSERT_EQ(got.p.size(), 5u);
  ASSERT_EQ(got.n.size(), 5u);
  ASSERT_EQ(got.uv.size(), 5u);
  for (size_t v = 0; v < 5; ++v) {
    EXPECT_NEAR(got.p[v].y, m.p[3 * v + 1], 1e-6f);
    EXPECT_NEAR(got.n[v].z, m.n[3 * v + 2], 1e-6f);
    EXPECT_NEAR(got.uv[v].y, m.uv[2 * v + 1], 1e-6f);
  }
  // The quad (3, 2, 4, 0) becomes (3, 2, 4) and (3, 4, 0), as pbrt-v4 splits it.
  EXPECT_EQ(got.indices, (std::vector<uint32_t>{0, 1, 2, 2, 3, 0, 3, 2, 4, 3, 4, 0}));
  EXPECT_EQ(got.skipped_faces, 0u);
}

TEST(PlyMesh, AsciiLittleAndBigEndianGiveTheSameMesh) {
  const SmallMesh m;
  for (Encoding e : {Encoding::Ascii, Encoding::Little, Encoding::Big}) {
    SCOPED_TRACE(static_cast<int>(e));
    expect_small_mesh(parse_ply_mesh(write_ply(m, e), "m.ply"));
  }
}

TEST(PlyMesh, TextureCoordinateNamesPbrtAccepts) {
  for (const char* names : {"u v", "s t", "texture_u texture_v", "texture_s texture_t"}) {
    SCOPED_TRACE(names);
    expect_small_mesh(parse_ply_mesh(write_ply(SmallMesh{}, Encoding::Little, names), "m.ply"));
  }
  // Names it does not know leave the mesh without uv.
  EXPECT_TRUE(parse_ply_mesh(write_ply(SmallMesh{}, Encoding::Little, "a b"), "m.ply").uv.empty());
}

TEST(PlyMesh, GzipCompressedFilesReadAsTheirContent) {
  TempDir dir;
  const std::string bytes = write_ply(SmallMesh{}, Encoding::Big);
  expect_small_mesh(load_ply_mesh(gzip(bytes, dir.file("m.ply.gz"))));
  // Through the loader, as a scene names it.
  gzip(bytes, dir.write("meshes/m.ply.gz", ""));
  SceneDesc s = load_world("Shape \"plymesh\" \"string filename\" \"meshes/m.ply.gz\"\n", dir.path());
  ASSERT_EQ(s.meshes.size(), 1u);
  EXPECT_EQ(s.meshes[0].indices.size(), 12u);
  // A truncated gzip stream is an error, not a short mesh.
  const std::string gz = gzip(bytes, dir.file("whole.ply.gz"));
  std::ifstream in(gz, std::ios::binary);
  std::string compressed((std::istreambuf_iterator<char>(in)), {});
  dir.write("cut.ply.gz", compressed.substr(0, compressed.size() / 2));
  EXPECT_THROW(load_ply_mesh(dir.file("cut.ply.gz")), SceneError);
}

// Files are read chunk by chunk: with chunks of a few bytes every value and
// the header's end straddle chunk boundaries, and the mesh is the same as
// read whole, plain or compressed; the errors are the same too.
TEST(PlyMesh, ReadInChunksGivesWhatTheWholeFileGives) {
  TempDir dir;
  for (Encoding e : {Encoding::Ascii, Encoding::Little, Encoding::Big}) {
    const std::string bytes = write_ply(SmallMesh{}, e);
    const std::string plain = dir.write("m" + std::to_string(static_cast<int>(e)) + ".ply", bytes);
    const std::string gz = gzip(bytes, dir.file("m" + std::to_string(static_cast<int>(e)) + ".ply.gz"));
    for (size_t chunk : {size_t(1), size_t(3), size_t(7), size_t(64), size_t(1) << 20}) {
      SCOPED_TRACE(std::to_string(static_cast<int>(e)) + " chunk " + std::to_string(chunk));
      expect_small_mesh(load_ply_mesh(plain, chunk));
      expect_small_mesh(load_ply_mesh(gz, chunk));
    }
    // Every truncation of the file on disk fails as it does in memory.
    const size_t last = e == Encoding::Ascii ? bytes.rfind(' ') : bytes.size();
    for (size_t len = 0; len < last; len += 5) {
      SCOPED_TRACE(len);
      dir.write("cut.ply", bytes.substr(0, len));
      EXPECT_THROW(load_ply_mesh(dir.file("cut.ply"), 4), SceneError);
    }
  }
}

TEST(PlyMesh, HeaderEndFoundOnlyAtTheStartOfALine) {
  TempDir dir;
  std::string bytes = write_ply(SmallMesh{}, Encoding::Little);
  // A comment mentioning end_header, and a header longer than one read.
  bytes.insert(bytes.find("comment"), "comment end_header is not here\ncomment " + std::string(200000, 'x') + "\n");
  expect_small_mesh(load_ply_mesh(dir.write("long.ply", bytes), 5));
  // No end_header at all, in a file longer than the header is allowed to be.
  std::string endless = "ply\nformat ascii 1.0\n";
  while (endless.size() < (size_t(17) << 20)) endless += "comment " + std::string(1000, 'y') + "\n";
  try {
    load_ply_mesh(dir.write("endless.ply", endless));
    ADD_FAILURE() << "no error";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("no end_header"), std::string::npos) << e.what();
  }
}

// An over-long number in an ASCII body is malformed, whatever the chunking.
TEST(PlyMesh, OverlongAsciiNumberIsMalformed) {
  TempDir dir;
  std::string bytes = header(Encoding::Ascii, 1, 1) + std::string(2000, '1') + " 0 0 0 0 1 0 0\n3 0 0 0\n";
  EXPECT_NE(parse_error(bytes).find("malformed number '111"), std::string::npos);
  try {
    load_ply_mesh(dir.write("long.ply", bytes), 16);
    ADD_FAILURE() << "no error";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("malformed number '111"), std::string::npos) << e.what();
  }
}

TEST(PlyMesh, EveryTruncationIsAnErrorNotACrash) {
  for (Encoding e : {Encoding::Ascii, Encoding::Little, Encoding::Big}) {
    const std::string whole = write_ply(SmallMesh{}, e);
    // ASCII: a cut inside the last number still parses as a (shorter) number,
    // so cut at least one whole value off the end.
    const size_t last = e == Encoding::Ascii ? whole.rfind(' ') : whole.size();
    for (size_t len = 0; len < last; ++len) {
      SCOPED_TRACE(len);
      EXPECT_NE(parse_error(whole.substr(0, len)), "");
    }
  }
  const std::string binary = write_ply(SmallMesh{}, Encoding::Little);
  EXPECT_NE(parse_error(binary.substr(0, binary.size() - 10)).find("truncated"), std::string::npos);
}

TEST(PlyMesh, HeaderWithoutEndHeaderIsAnError) {
  const std::string h = header(Encoding::Ascii, 3, 1);
  EXPECT_NE(parse_error(h.substr(0, h.find("end_header"))).find("no end_header"), std::string::npos);
  EXPECT_NE(parse_error("not a ply\n").find("not a PLY file"), std::string::npos);
  EXPECT_NE(parse_error("ply\nelement vertex 1\nend_header\n").find("no format"), std::string::npos);
  EXPECT_NE(parse_error("ply\nformat ascii 1.0\nwhatever\nend_header\n").find("unknown keyword 'whatever'"),
            std::string::npos);
  EXPECT_NE(parse_error("ply\nformat ascii 1.0\nelement vertex -3\nend_header\n").find("not a non-negative integer"),
            std::string::npos);
  // A binary body read as header lines: its bytes are escaped and cut short in the message.
  const std::string binary = parse_error(std::string("ply\nformat binary_little_endian 1.0\n\x01\x02\x7f") +
                                         std::string(100, 'z') + "\n");
  EXPECT_NE(binary.find("unknown keyword '\\x01\\x02\\x7fzzz"), std::string::npos) << binary;
  EXPECT_NE(binary.find("...'"), std::string::npos) << binary;
  for (char c : binary) EXPECT_FALSE(static_cast<unsigned char>(c) < 0x20 || c == 0x7f) << binary;
}

TEST(PlyMesh, IndicesOutsideTheVertexListAreErrors) {
  for (int bad : {5, 100000, -1}) {
    SmallMesh m;
    m.faces[1] = {0, bad, 1};
    for (Encoding e : {Encoding::Ascii, Encoding::Little}) {
      const std::string msg = parse_error(write_ply(m, e));
      EXPECT_NE(msg.find("face 1: vertex index " + std::to_string(bad) + " out of range (5 vertices)"), std::string::npos)
          << msg;
    }
  }
  // Through the loader the message names the scene file and line.
  TempDir dir;
  SmallMesh m;
  m.faces[0] = {0, 1, 7};
  dir.write("bad.ply", write_ply(m, Encoding::Little));
  const std::string e = load_error("WorldBegin\n\nShape \"plymesh\" \"string filename\" \"bad.ply\"\n", dir.path());
  EXPECT_NE(e.find("bad.pbrt:3: cannot read PLY"), std::string::npos) << e;
  EXPECT_NE(e.find("vertex index 7 out of range"), std::string::npos) << e;
}

TEST(PlyMesh, FacesThatAreNeitherTrianglesNorQuadsAreSkippedAndCounted) {
  SmallMesh m;
  m.faces = {{0, 1, 2}, {0, 1, 2, 3, 4}, {0, 1}};
  PlyMesh got = parse_ply_mesh(write_ply(m, Encoding::Little), "m.ply");
  EXPECT_EQ(got.indices, (std::vector<uint32_t>{0, 1, 2}));
  EXPECT_EQ(got.skipped_faces, 2u);
  m.faces = {{0, 1, 2, 3, 4}};
  EXPECT_NE(parse_error(write_ply(m, Encoding::Little)).find("no triangles or quads"), std::string::npos);
  // The loader says so.
  TempDir dir;
  m.faces = {{0, 1, 2}, {0, 1, 2, 3, 4}};
  dir.write("poly.ply", write_ply(m, Encoding::Ascii));
  SceneDesc s = load_world("Shape \"plymesh\" \"string filename\" \"poly.ply\"\n", dir.path());
  bool warned = false;
  for (const std::string& w : s.warnings) warned |= w.find("1 faces that are neither triangles nor quads") != std::string::npos;
  EXPECT_TRUE(warned);
}

TEST(PlyMesh, NothingAfterEndHeaderIsTruncationNotAnOverread) {
  // end_header as the very last bytes, without a newline, with huge counts.
  for (const char* format : {"ascii", "binary_little_endian"}) {
    const std::string h = std::string("ply\nformat ") + format +
                          " 1.0\nelement vertex 4000000000\nproperty float x\nproperty float y\nproperty float z\n"
                          "element face 1\nproperty list uchar int vertex_indices\nend_header";
    EXPECT_NE(parse_error(h).find("truncated"), std::string::npos) << format;
  }
  // An out-of-range index given as a huge or non-integral number is named, not cast.
  const std::string ascii = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                            "element face 1\nproperty list uchar double vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n"
                            "3 0 1 1e300\n";
  EXPECT_NE(parse_error(ascii).find("vertex index 1e+300 out of range"), std::string::npos) << parse_error(ascii);
}

TEST(PlyMesh, CountsBeyondTheBytesLeftAreRefusedBeforeAllocating) {
  // Four billion vertices declared, a few bytes given: an error, at once.
  std::string bytes = header(Encoding::Little, 4000000000u, 1) + std::string(64, '\0');
  EXPECT_NE(parse_error(bytes).find("declares 4000000000 vertex elements"), std::string::npos);
  // A list claiming 255 entries with fewer bytes left.
  std::string h = "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                  "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
  std::string body(36, '\0');
  body += static_cast<char>(255);
  body += std::string(12, '\0');
  EXPECT_NE(parse_error(h + body).find("longer than the bytes left"), std::string::npos);
}

TEST(PlyMesh, OtherElementsAndPropertyTypesAreReadPast) {
  // Vertex coordinates as doubles and shorts, an extra list on vertices, an
  // edge element between vertices and faces, face_indices after the indices.
  std::string bytes =
      "ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty double x\nproperty short y\n"
      "property float z\nproperty list uchar uchar tags\nproperty uchar red\nelement edge 2\nproperty int a\n"
      "property int b\nelement face 1\nproperty list ushort uint vertex_indices\nproperty int face_indices\nend_header\n";
  const double xs[3] = {0.5, 1.5, 2.5};
  for (int v = 0; v < 3; ++v) {
    put(bytes, xs[v], Encoding::Big);
    put(bytes, static_cast<int16_t>(-v), Encoding::Big);
    put(bytes, 3.f, Encoding::Big);
    put(bytes, static_cast<uint8_t>(2), Encoding::Big);
    put(bytes, static_cast<uint8_t>(7), Encoding::Big);
    put(bytes, static_cast<uint8_t>(8), Encoding::Big);
    put(bytes, static_cast<uint8_t>(200), Encoding::Big);
  }
  for (int e = 0; e < 4; ++e) put(bytes, static_cast<int32_t>(e), Encoding::Big);
  put(bytes, static_cast<uint16_t>(3), Encoding::Big);
  for (uint32_t i : {2u, 1u, 0u}) put(bytes, i, Encoding::Big);
  put(bytes, static_cast<int32_t>(42), Encoding::Big);
  PlyMesh m = parse_ply_mesh(bytes, "m.ply");
  ASSERT_EQ(m.p.size(), 3u);
  EXPECT_EQ(m.p[2], Vec3(2.5f, -2.f, 3.f));
  EXPECT_TRUE(m.n.empty());
  EXPECT_EQ(m.indices, (std::vector<uint32_t>{2, 1, 0}));
}

TEST(PlyMesh, FacesMayComeBeforeVertices) {
  // RPly (and so pbrt-v4) reads elements in any order.
  const std::string bytes =
      "ply\nformat ascii 1.0\nelement face 1\nproperty list uchar int vertex_indices\nelement vertex 3\n"
      "property float x\nproperty float y\nproperty float z\nend_header\n3 2 1 0\n0 0 0\n1 0 0\n0 1 0\n";
  PlyMesh m = parse_ply_mesh(bytes, "m.ply");
  EXPECT_EQ(m.indices, (std::vector<uint32_t>{2, 1, 0}));
  ASSERT_EQ(m.p.size(), 3u);
  EXPECT_EQ(m.p[1], Vec3(1.f, 0.f, 0.f));
  // ...and their indices are still checked against the declared vertices.
  const std::string bad = std::string(bytes).replace(bytes.find("3 2 1 0"), 7, "3 2 1 3");
  EXPECT_NE(parse_error(bad).find("vertex index 3 out of range (3 vertices)"), std::string::npos);
}

TEST(PlyMesh, NonFiniteVertexValuesAreErrors) {
  std::string bytes = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                      "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n";
  EXPECT_NE(parse_error(bytes).find("vertex 1 has a non-finite"), std::string::npos);
}

// Random byte mutations of valid files: each either parses into a mesh whose
// indices are all in range or is refused with a SceneError.
TEST(PlyMesh, MutatedFilesParseOrFailCleanly) {
  std::mt19937 rng(7);
  size_t parsed = 0, refused = 0;
  for (Encoding e : {Encoding::Ascii, Encoding::Little, Encoding::Big}) {
    const std::string whole = write_ply(SmallMesh{}, e);
    for (int trial = 0; trial < 3000; ++trial) {
      std::string bytes = whole;
      const int edits = 1 + static_cast<int>(rng() % 4);
      for (int k = 0; k < edits; ++k) bytes[rng() % bytes.size()] = static_cast<char>(rng() % 256);
      try {
        PlyMesh m = parse_ply_mesh(bytes, "m.ply");
        for (uint32_t i : m.indices) ASSERT_LT(i, m.p.size());
        ++parsed;
      } catch (const SceneError&) {
        ++refused;
      }
    }
  }
  EXPECT_GT(parsed, 0u);
  EXPECT_GT(refused, 0u);
}

}  // namespace
}  // namespace tessera
