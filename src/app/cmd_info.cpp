// tessera info SCENE: what the loader made of a scene file.
#include <cstdio>
#include <map>

#include "app/commands.h"
#include "app/scene_loading.h"
#include "kernels/effects.h"
#include "scene/pbrt_film.h"
#include "scene/scene_effects.h"
#include "scene/spectral_choice.h"
#include "scene/system_memory.h"
#include "render/scene_data.h"

namespace tessera {
namespace {

int run_info(const std::string& path) {
  const std::optional<uint64_t> start = resident_bytes();
  SceneDesc desc = load_scene_or_builtin(path);
  const std::optional<uint64_t> read_peak = peak_resident_bytes();
  const size_t materials = desc.materials.size(), textures = desc.textures.size(), meshes = desc.meshes.size();
  std::map<std::string, int> light_kinds;
  for (const Light& l : desc.lights) {
    static const char* names[] = {"area", "point", "spot", "distant", "infinite"};
    ++light_kinds[names[static_cast<int>(l.type)]];
  }
  // Before SceneData empties the meshes, whose areas --spectral auto weighs.
  const std::string why = spectral_reason(desc);
  const Rgb shift = multibounce_colour_shift(desc);
  SceneData scene(std::move(desc));
  const std::optional<uint64_t> built = resident_bytes();
  const SceneView& v = scene.view();
  std::printf("scene:          %s\n", scene.desc().source.c_str());
  std::printf("resolution:     %s, %d spp, max depth %d\n", describe_film_size(v.camera).c_str(), scene.desc().spp,
              scene.desc().max_depth);
  std::printf("shapes:         %zu meshes, %zu triangles", meshes, scene.num_triangles());
  if (v.num_instances > 0)
    std::printf(" (%u instances of %u objects, whose triangles are counted once)", v.num_instances, v.num_prototypes);
  std::printf("\n");
  std::printf("materials:      %zu\n", materials);
  std::printf("textures:       %zu (%zu images)\n", textures, scene.desc().images.size());
  uint32_t area = 0;
  for (uint32_t i = 0; i < v.num_lights; ++i) area += v.lights[i].type == LightType::Area;
  std::printf("lights:         %u (%u emissive triangles", v.num_lights, area);
  for (auto& [k, n] : light_kinds) std::printf(", %d %s", n, k.c_str());
  std::printf(")\n");
  if (!scene.desc().media.empty() || scene.desc().camera_medium >= 0) {
    size_t grids = 0, stored_bricks = 0, glowing = 0;
    for (const Medium& m : scene.desc().media) {
      if (m.grid < 0) continue;
      ++grids;
      glowing += m.grid_emits != 0;
      stored_bricks += scene.desc().grids[static_cast<size_t>(m.grid)].density.values.size() / kBrickVoxels;
    }
    std::printf("media:          %zu homogeneous, %zu grids (%zu density bricks of 8^3, %zu glowing by grid)%s\n",
                scene.desc().media.size() - grids, grids, stored_bricks, glowing,
                scene.desc().camera_medium >= 0 ? ", the camera in one" : "");
  }
  const Bounds& b = scene.bounds();
  // Bounds in the scene file's world (render space plus its origin, in double).
  const glm::dvec3 o = scene.desc().render_origin;
  if (scene.num_triangles() > 0)
    std::printf("bounds:         (%g, %g, %g) - (%g, %g, %g)\n", o.x + b.lo.x, o.y + b.lo.y, o.z + b.lo.z,
                o.x + b.hi.x, o.y + b.hi.y, o.z + b.hi.z);
  std::printf("effects:        %s\n", describe_effects(scene.effects()).c_str());
  std::printf("specialisation: %s\n", describe_specialisation(specialisation_for(scene.effects())).c_str());
  std::printf("transport:      %s\n", why.empty() ? "rgb (--spectral auto)" : ("spectral (--spectral auto: " + why + ")").c_str());
  std::printf("colour shift:   %.2f %.2f %.2f %% (RGB against spectral transport after maxdepth diffuse bounces, estimated)\n",
              100.0 * shift.x, 100.0 * shift.y, 100.0 * shift.z);
  std::printf("warnings:       %zu\n", scene.desc().warnings.size());
  // Above what the process held before reading: what reading the files took
  // at its peak, and what the built scene keeps (its BVH comes on top when rendering).
  if (start && read_peak && built)
    std::printf("memory:         reading peaked at %s, the built scene holds %s\n",
                format_bytes(*read_peak > *start ? *read_peak - *start : 0).c_str(),
                format_bytes(*built > *start ? *built - *start : 0).c_str());
  return 0;
}

}  // namespace

CommandRunner add_info_command(CLI::App& app) {
  auto path = std::make_shared<std::string>();
  CLI::App* c = app.add_subcommand("info", "Print counts, bounds and the effects set of a scene");
  c->add_option("scene", *path, "Scene file in pbrt-v4 syntax (omit for the built-in Cornell box)");
  return [path] { return run_info(*path); };
}

}  // namespace tessera
