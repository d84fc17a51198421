// Shared helpers for the pbrt loader tests.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "scene/pbrt_loader.h"

namespace tessera::test {

// A fresh directory per test, removed at the end.
class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = std::filesystem::temp_directory_path() /
            ("tessera_scene_" + std::to_string(::getpid()) + "_" + info->test_suite_name() + "_" + info->name());
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~TempDir() { std::filesystem::remove_all(path_); }
  std::string path() const { return path_.string(); }
  std::string file(const std::string& name) const { return (path_ / name).string(); }
  std::string write(const std::string& name, const std::string& text) const {
    std::filesystem::create_directories((path_ / name).parent_path());
    std::ofstream(path_ / name, std::ios::binary) << text;
    return file(name);
  }

 private:
  std::filesystem::path path_;
};

// Parses a world block (WorldBegin is prepended).
inline SceneDesc load_world(const std::string& body, const std::string& dir = ".") {
  return load_pbrt_string("WorldBegin\n" + body, "test.pbrt", dir);
}

// The message of the SceneError that loading `text` throws ("" if none).
inline std::string load_error(const std::string& text, const std::string& dir = ".") {
  try {
    load_pbrt_string(text, "bad.pbrt", dir);
  } catch (const SceneError& e) {
    return e.what();
  }
  return "";
}

// The message of the SceneError that loading the file at `path` throws ("" if none).
inline std::string load_file_error(const std::string& path) {
  try {
    load_pbrt_file(path);
  } catch (const SceneError& e) {
    return e.what();
  }
  return "";
}

inline Vec3 geometric_normal(const MeshDesc& m, size_t tri) {
  Vec3 p0 = m.p[m.indices[3 * tri]], p1 = m.p[m.indices[3 * tri + 1]], p2 = m.p[m.indices[3 * tri + 2]];
  Vec3 n = glm::normalize(glm::cross(p0 - p2, p1 - p2));
  return m.flip_normals ? -n : n;
}

inline double surface_area(const MeshDesc& m) {
  double a = 0.;
  for (size_t t = 0; t < m.indices.size() / 3; ++t) {
    Vec3 p0 = m.p[m.indices[3 * t]], p1 = m.p[m.indices[3 * t + 1]], p2 = m.p[m.indices[3 * t + 2]];
    a += 0.5 * glm::length(glm::cross(p1 - p0, p2 - p0));
  }
  return a;
}

constexpr const char* kTriangle = "Shape \"trianglemesh\" \"point3 P\" [ 0 0 0  1 0 0  0 1 0 ] \"integer indices\" [ 0 1 2 ]\n";

}  // namespace tessera::test

#define EXPECT_VEC3_NEAR(a, b, eps)        \
  do {                                     \
    EXPECT_NEAR((a).x, (b).x, eps);        \
    EXPECT_NEAR((a).y, (b).y, eps);        \
    EXPECT_NEAR((a).z, (b).z, eps);        \
  } while (0)
