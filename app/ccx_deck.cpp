#include "app/ccx_deck.hpp"

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <ostream>
#include <string>

#include "fem/nc_ties.hpp"
#include "mesher/mesh/atomic_file.hpp"
#include "mesher/mesh/mesh_io.hpp"

namespace hexfem {
namespace {

// A number in at most 20 characters, the field ccx 2.20 reads (it refuses a longer one): the
// shortest round-trip form when it fits, else as many digits as fit.
std::string ccx_number(double v) {
  char buf[32];
  auto r = std::to_chars(buf, buf + sizeof buf, v);
  for (int digits = 16; r.ptr - buf > 20 && digits > 1; --digits)
    r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::general, digits);
  return std::string(buf, r.ptr);
}

}  // namespace

std::vector<std::filesystem::path> write_ccx_deck(const MixedMesh& mesh,
                                                  const ModalOptions& options,
                                                  const std::vector<std::uint8_t>& fixed,
                                                  const std::filesystem::path& deck) {
  std::filesystem::path mesh_file = deck;
  mesh_file.replace_filename(deck.stem().string() + "_mesh.inp");
  write_inp(mesh, mesh_file, node_tie_list(nc_face_ties(mesh, fixed)),
            mesh.order == 1 && options.incompatible_hex);

  // A consistent system in the mesh's length unit L (s metres), newtons and seconds: stress in
  // N/L^2, mass in N s^2/L, so E' = E s^2 and rho' = rho s^4 (mm: MPa and t/mm^3).
  const double s = options.length_scale, E_scale = s * s, rho_scale = s * s * s * s;
  std::vector<std::int32_t> solids = mesh.cell_solid;
  std::sort(solids.begin(), solids.end());
  solids.erase(std::unique(solids.begin(), solids.end()), solids.end());
  write_atomically(deck, false, [&](std::ostream& out) {
    char buf[256];
    std::snprintf(buf, sizeof buf,
                  "** hexfem modal as a CalculiX deck: lengths as in the mesh (%g m each), N, s; "
                  "frequencies in Hz\n",
                  s);
    out << buf << "*INCLUDE, INPUT=" << mesh_file.filename().string() << "\n";
    for (std::int32_t solid : solids) {
      const Material& m = options.material.of(solid);
      out << "*MATERIAL, NAME=M" << solid << "\n** " << m.name << "\n*ELASTIC\n"
          << ccx_number(m.E * E_scale) << ", " << ccx_number(m.nu) << "\n*DENSITY\n"
          << ccx_number(m.rho * rho_scale) << "\n*SOLID SECTION, ELSET=SOLID_" << solid
          << ", MATERIAL=M" << solid << "\n";
    }
    bool header = false;
    for (std::size_t v = 0; 3 * v < fixed.size(); ++v) {
      int first = -1;
      for (int d = 0; d <= 3; ++d) {  // runs of fixed components: "node, first, last"
        const bool f = d < 3 && fixed[3 * v + d];
        if (f && first < 0) first = d;
        if (f || first < 0) continue;
        if (!header) out << "*BOUNDARY\n";
        header = true;
        out << v + 1 << ", " << first + 1 << ", " << d << "\n";
        first = -1;
      }
    }
    out << "*STEP\n*FREQUENCY\n" << options.num_modes << "\n*END STEP\n";
  });
  return {deck, mesh_file};
}

}  // namespace hexfem
