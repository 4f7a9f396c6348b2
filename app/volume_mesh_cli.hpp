// `hexfem mesh --dim 3`: the whole pipeline from a CAD file to a written hex-dominant mesh.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "mesher/pipeline.hpp"

namespace hexfem {

struct VolumeMeshArgs {
  std::string file;
  MeshOptions options;
  std::string output;  // empty: no file written
  bool json = false;
  bool binary = false;  // MSH 4.1 binary
  bool force = false;   // write a mesh whose volume is more than 10 % off the CAD's
  int order = 1;        // 2: mid-edge nodes on the CAD geometry
};

// Meshes (mesh_part emits only valid meshes), refuses a volume far off the CAD's, and writes;
// prints the paper's table row, the volume error and the time per stage (or JSON). Returns the exit
// code.
int run_volume_mesh(const VolumeMeshArgs& args);

// The recombination's options (`mesh` and `recombine`): --min-quality, --max-gap, --no-prisms,
// --no-pyramids, --no-nc-repair, --conformal, --nc-hex-gain, --hex-selection.
void add_recombination_options(CLI::App& sub, VolumeOptions& v, std::string& hex_selection);

}  // namespace hexfem
