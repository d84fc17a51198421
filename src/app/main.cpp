// tessera: physically based rendering with learned path guiding.
#include <cstdio>
#include <new>
#include <exception>
#include <map>

#include "app/commands.h"
#include "scene/scene_desc.h"

#if defined(__GLIBC__)
#include <malloc.h>
#endif

int main(int argc, char** argv) {
#if defined(__GLIBC__)
  // Buffers from 256 KiB up are mapped from the system and returned to it
  // when freed. By default glibc raises this threshold to the size of each
  // mapped buffer freed, so that after the first large free while a scene
  // was read the next arrays came from its heap, which it rarely returns: a
  // big mesh peaked higher and kept its transient arrays resident for the
  // whole render. Rendering speed does not depend on it (measured).
  mallopt(M_MMAP_THRESHOLD, 256 * 1024);
#endif
  CLI::App app{"tessera " TESSERA_VERSION " - path tracing with learned guiding (pbrt-v4 scenes, OpenEXR out)"};
  app.set_version_flag("--version", TESSERA_VERSION);
  app.require_subcommand(0, 1);
  std::map<CLI::App*, tessera::CommandRunner> runners;
  auto add = [&](tessera::CommandRunner (*fn)(CLI::App&)) {
    size_t before = app.get_subcommands({}).size();
    tessera::CommandRunner r = fn(app);
    runners[app.get_subcommands({})[before]] = r;
  };
  add(tessera::add_render_command);
  add(tessera::add_info_command);
  add(tessera::add_compare_command);
  add(tessera::add_bench_rays_command);
  add(tessera::add_guide_viz_command);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  try {
    for (auto& [sub, run] : runners)
      if (sub->parsed()) return run();
    std::fputs(app.help().c_str(), stdout);
    return 0;
  } catch (const tessera::SceneError& e) {
    std::fprintf(stderr, "tessera: error: %s\n", e.what());
    return 2;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "tessera: error: out of memory (a smaller --res, fewer --threads or a smaller scene may fit)\n");
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "tessera: error: %s\n", e.what());
    return 1;
  }
}
