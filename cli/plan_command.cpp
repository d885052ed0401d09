// `shadowbake plan SCENE`: the convolution method's hierarchy of (light part, blocker cluster,
// receiver part) triples per receiver, with penumbra error, image sizes and estimated cost,
// without baking (docs/cli.md).
#include <fmt/core.h>

#include <optional>

#include "commands.h"
#include "pipeline/bake.h"

namespace sbcli {

Runner add_plan_command(CLI::App& app) {
  struct Options {
    std::string scene;
    int resolution = 0;
    double error_texels = 0;
    int threads = 0;
  };
  auto o = std::make_shared<Options>();
  auto* cmd = app.add_subcommand(
      "plan", "print the convolution's triples (penumbra error, image sizes, cost) per receiver");
  cmd->add_option("scene", o->scene, "scene file (TOML, docs/scene-format.md)")->required();
  auto* resolution_opt = cmd->add_option("--resolution", o->resolution, "texels per side")
                             ->check(CLI::Range(1, 16384));
  auto* error_opt = cmd->add_option("--error-texels", o->error_texels,
                                    "penumbra error allowed, receiver texels (overrides [bake])")
                        ->check(CLI::PositiveNumber);
  cmd->add_option("--threads", o->threads, "worker threads (0: all cores)")
      ->check(CLI::Range(0, 1024));
  return [=]() {
    auto scene = sb::load_scene(o->scene);
    if (!scene) return fail(scene.error());
    if (*resolution_opt) scene->bake.resolution = o->resolution;
    if (*error_opt) set_setting(scene->bake, "error_texels", o->error_texels);
    sb::BakeOptions options;
    options.threads = o->threads;
    scene->bake.method = "convolution";  // the plan `plan` shows (docs/cli.md)
    auto plans = sb::plan(*scene, options);
    if (!plans) return fail(plans.error());
    for (const auto& text : *plans) fmt::print("{}", text);
    return int(ok);
  };
}

}  // namespace sbcli
