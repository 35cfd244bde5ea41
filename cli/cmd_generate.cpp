// `erodem generate`: seeded synthetic terrain written as a GeoTIFF.
#include <cstdio>

#include "commands.hpp"
#include "erodem/grid.hpp"
#include "erodem/io/raster.hpp"
#include "erodem/terrain_synth.hpp"

namespace erodem::cli {

namespace {

struct GenerateOptions {
  std::string kind, output;
  int size = 256;
  std::uint64_t seed = 1;
  double relief = 100.0, cell_size = 10.0;
  bool overwrite = false;
};

int generate(const GenerateOptions& o) {
  const SynthKind kind = synth_kind_from_string(o.kind);
  check_output_path(o.output, o.overwrite);
  const Grid grid = Grid::uniform(o.size, o.size, o.cell_size);
  const auto heights = generate_terrain(kind, o.size, o.size, o.cell_size, o.relief, o.seed);
  const std::vector<float> f32(heights.begin(), heights.end());
  io::write_geotiff(o.output, grid, f32,
                    "synthetic " + o.kind + " terrain, seed " + std::to_string(o.seed) + " (m)");
  std::printf("wrote %s: %s, %d x %d cells of %g m, relief %g m, seed %llu\n", o.output.c_str(),
              o.kind.c_str(), o.size, o.size, o.cell_size, o.relief,
              static_cast<unsigned long long>(o.seed));
  return 0;
}

}  // namespace

Action add_generate(CLI::App& app) {
  auto o = std::make_shared<GenerateOptions>();
  auto* sub = app.add_subcommand("generate", "Write a synthetic terrain as a GeoTIFF");
  std::vector<std::string> kinds = synth_kind_names();
  sub->add_option("--kind", o->kind, "Terrain kind")->required()->check(CLI::IsMember(kinds));
  sub->add_option("--size", o->size, "Cells per side")->check(CLI::Range(2, 32768));
  sub->add_option("--seed", o->seed, "Random seed (same seed, same terrain)");
  sub->add_option("--relief", o->relief, "Elevation range (m)")->check(CLI::PositiveNumber);
  sub->add_option("--cell-size", o->cell_size, "Cell size (m)")->check(CLI::PositiveNumber);
  sub->add_flag("--overwrite", o->overwrite, "Replace an existing file");
  sub->add_option("output", o->output, "Output GeoTIFF")->required();
  return [o] { return generate(*o); };
}

}  // namespace erodem::cli
