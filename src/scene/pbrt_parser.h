// Walks pbrt-v4 directives, keeping pbrt's graphics state (transform,
// orientation, material, area light, media; AttributeBegin/End stack; named
// coordinate systems; object instances) and filling a SceneDesc.
#pragma once

#include <map>
#include <istream>
#include <string>
#include <vector>

#include "scene/pbrt_context.h"
#include "scene/pbrt_tokenizer.h"

namespace tessera {

class PbrtParser {
 public:
  // `search_dir`: the main file's directory, the fallback for relative names.
  explicit PbrtParser(std::string search_dir);

  // Parses one file, read from `in` in chunks (Include/Import recurse into
  // here). Returns its last line. Throws SceneError.
  int parse_stream(std::istream& in, const std::string& file_name, const std::string& including_dir);

  // Checks for a missing WorldBegin and an empty scene, reporting `file:last_line`.
  SceneDesc finish(const std::string& file_name, int last_line);

 private:
  // Transforms are composed in double: a scene placed far from the origin
  // (Translate 1e6 ...) then cancels exactly against render space's
  // translation, and only the result is rounded to float.
  using DMat4 = glm::dmat4;
  struct GraphicsState {
    DMat4 ctm{1.0};      // at the start of the transform interval (TransformTimes)
    DMat4 ctm_end{1.0};  // at its end: differs for moving shapes (motion blur)
    bool active_start = true, active_end = true;  // ActiveTransform
    bool reverse_orientation = false;
    int32_t material = 0;
    int32_t area_light = -1;
    MediumInterface media;  // MediumInterface "inside" "outside" (-1: vacuum)
  };
  struct StackEntry {
    char kind;  // 'a' AttributeBegin, 't' TransformBegin, 'o' ObjectBegin
    GraphicsState state;
    std::string where;
  };

  void parse_tokens(TokenStream& tokens, const std::string& including_dir);
  void directive(TokenStream& tokens, size_t& pos, const std::string& including_dir);
  void shape(const Token& at, const std::string& type, const ParamSet& params, const std::string& including_dir);
  void camera(const Token& at, const std::string& type, const ParamSet& params);
  // Fails unless every vertex (and its end position when it moves) is within
  // the range single-precision ray tracing represents.
  void check_coordinates(const MeshDesc& mesh, const Token& at) const;
  bool placed_within_range(uint32_t object, const InstanceDesc& inst);
  void object_instance(const Token& at, uint32_t object);
  void push(char kind, const Token& at);
  void pop(char kind, const Token& at);
  void require_world(const Token& at, bool inside) const;
  void resolve_media();  // MediumInterface names -> media (pbrt-v4 resolves them at the end too)
  DirectiveContext context(const Token& at, const std::string& including_dir);

  SceneDesc scene_;
  NamedObjects names_;
  std::string search_dir_;
  GraphicsState state_;
  std::vector<StackEntry> stack_;
  struct CoordinateSystem {
    DMat4 start, end;    // the transforms at the start and end of the transform interval
    bool render_space;   // saved after WorldBegin (or the camera's): relative to render space, not world
  };
  std::map<std::string, CoordinateSystem> coordinate_systems_;
  // pbrt-v4's render space ("cameraworld"): the world translated so that the
  // camera sits at the origin. Everything after WorldBegin is placed there,
  // so a scene far from the world's origin keeps float precision near the
  // camera; SceneDesc::render_origin says where that origin is in the world.
  DMat4 render_from_world_{1.0};
  DMat4 world_from_render_{1.0};
  std::map<std::string, uint32_t> objects_;  // ObjectBegin names -> SceneDesc::objects (the latest definition)
  std::string open_instance_;  // non-empty between ObjectBegin and ObjectEnd
  struct ObjectBox {
    Vec3 lo{INFINITY}, hi{-INFINITY};
    bool known = false;
  };
  std::vector<ObjectBox> object_boxes_;  // per SceneDesc::objects entry, from its first instance
  struct MediumRef {
    int16_t code;       // what MeshDesc::media holds until resolve_media(): -2 - k
    std::string where;  // the first MediumInterface naming it
  };
  std::map<std::string, MediumRef> medium_refs_;
  bool world_begun_ = false;
  int include_depth_ = 0;
};

}  // namespace tessera
