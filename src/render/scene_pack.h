// A scene's arrays and its BVH packed into one buffer, for a device: every
// array a SceneView points to (and the arrays inside its images and
// environment distributions) copied back to back, plus the list of every
// pointer to patch for wherever the buffer lands. One allocation and one
// copy upload the whole scene (render/device_backend.cpp); on the CPU the
// emulated device renders from the packed copy (tests/render/device_backend_test.cpp).
// Grid media are not packed yet: such scenes throw std::runtime_error.
#pragma once

#include <cstddef>
#include <cstdint>
#include <iosfwd>
#include <vector>

#include "kernels/bvh.h"
#include "kernels/scene_view.h"

namespace tessera {

class PackedScene {
 public:
  PackedScene(const SceneView& scene, const BvhView& bvh);
  // A packed scene as save() wrote it (the GPU check programs read scenes
  // packed on a machine with the full build). Same build and machine kind
  // only: the views are stored as their bytes. Throws std::runtime_error.
  static PackedScene load(std::istream& in);
  void save(std::ostream& out) const;
  // Bytes of the buffer (a multiple of 16; the buffer must be 16-byte aligned).
  size_t size() const { return bytes_.size(); }
  // The buffer's contents for base address `base`, written to `out` (size() bytes).
  void write_for(uintptr_t base, unsigned char* out) const;
  // The views of the buffer when it is at `base`.
  SceneView view_at(uintptr_t base) const;
  BvhView bvh_at(uintptr_t base) const;

 private:
  struct Fixup {
    bool in_views;  // a pointer field of views_ (else a pointer inside bytes_)
    size_t at;      // its byte offset in views_ or in bytes_
  };
  PackedScene() = default;
  template <class T>
  size_t append(const T* data, size_t count);
  template <class T>
  void point_view(const T*& field, const T* data, size_t count);
  template <class T>
  void point_bytes(size_t field_at, const T* data, size_t count);
  void pack_images(const SceneView& s);
  void pack_env_distributions(const SceneView& s);
  // Adds base to the pointer stored at object + at.
  static void patch(unsigned char* object, size_t at, uintptr_t base);

  struct Views {
    SceneView scene;
    BvhView bvh;
  } views_;
  std::vector<unsigned char> bytes_;
  std::vector<Fixup> fixups_;
};

}  // namespace tessera
