// CalculiX (ccx) as an independent reference for the modal solver: writes a complete *FREQUENCY
// deck for a mixed mesh and reads the eigenvalues back from the .dat file. Used by the tests and
// validation/bench_modal (never by the CLI); part of the test-support library.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <iosfwd>
#include <string>
#include <vector>

#include "fem/material.hpp"
#include "mesher/mesh/mixed_mesh.hpp"

namespace hexfem {

// Deck in SI units (coordinates * length_scale): nodes, C3D8 / C3D6 / C3D4 elements (pyramids as
// C3D8 with the apex repeated, CalculiX has no pyramid), one *BOUNDARY line per fixed DOF
// (mask as select_fixed_dofs), the material (one per solid when given per solid) and a
// *FREQUENCY step for `modes` eigenvalues.
void write_ccx_frequency_deck(std::ostream& out, const MixedMesh& mesh,
                              const std::vector<std::uint8_t>& fixed, const SolidMaterials& mats,
                              int modes, double length_scale = 1.0);

struct CcxModalOutput {
  std::vector<double> eigenvalues;  // ω² as printed in E I G E N V A L U E   O U T P U T
  std::vector<double> frequencies;  // Hz, from the eigenvalues
  // Effective modal mass (x, y, z) per mode from E F F E C T I V E   M O D A L   M A S S, and
  // the x entry of T O T A L   E F F E C T I V E   M A S S: the mass the free DOFs carry (rᵀMr
  // over free DOFs, less than ρV when DOFs are fixed); 0 when absent.
  std::vector<std::array<double, 3>> effective_mass;
  double total_mass = 0;
};
// Parses a ccx .dat; throws hexfem::Error when it has no eigenvalue block.
CcxModalOutput parse_ccx_dat(std::istream& dat);

struct CcxRun {
  CcxModalOutput output;
  double seconds = 0;    // wall time of the ccx process
  long peak_rss_kb = 0;  // ccx's own peak resident memory (wait4 rusage)
  int exit_code = 0;
};
// Writes <dir>/<name>.inp, runs `ccx <name>` in `dir` with `threads` threads (OMP_NUM_THREADS,
// CCX_NPROC_EQUATION_SOLVER), and parses <dir>/<name>.dat. Throws hexfem::Error if ccx is not
// found, fails, or writes no eigenvalues (the tail of its log is in the message).
CcxRun run_ccx_frequency(const MixedMesh& mesh, const std::vector<std::uint8_t>& fixed,
                         const SolidMaterials& mats, int modes, const std::filesystem::path& dir,
                         const std::string& name = "modal", double length_scale = 1.0,
                         int threads = 1);

}  // namespace hexfem
