// tessera: physically based rendering with learned path guiding.
#include <cstdio>
#include <new>
#include <exception>
#include <map>

#include "app/commands.h"
#include "scene/scene_desc.h"

int main(int argc, char** argv) {
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
