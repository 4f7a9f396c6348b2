#include "app/ccx_deck.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <ostream>
#include <string>

#include "fem/element.hpp"
#include "fem/nc_ties.hpp"
#include "mesher/mesh/atomic_file.hpp"
#include "mesher/mesh/element_topology.hpp"
#include "mesher/mesh/mesh_io.hpp"

namespace hexfem {
namespace {

// The smallest det J of the 20-node hex x at the points of ref.
double min_det(const ReferenceElement& ref, const Vec3* x) {
  double lo = std::numeric_limits<double>::infinity();
  for (const ShapeValues& sv : ref.shape) lo = std::min(lo, jacobian_determinant(sv, x));
  return lo;
}

// Each tied node moved to its masters' weighted sum where that differs from where it is (its
// masters moved); the others keep their coordinates, bit for bit.
void follow_ties(MixedMesh& mesh, const NodeTies& ties) {
  if (ties.slot.empty()) return;
  for (std::size_t v = 0; v < mesh.nodes.size(); ++v) {
    const std::int32_t t = ties.slot[v];
    if (t < 0) continue;
    Vec3 x{0, 0, 0};
    for (int k = 0; k < kTieMasters; ++k) {
      const double w = ties.weight[kTieMasters * t + k];
      const Vec3& m = mesh.nodes[ties.master[kTieMasters * t + k]];
      for (int d = 0; d < 3; ++d) x[d] += w * m[d];
    }
    double off = 0, size = 0;
    for (int d = 0; d < 3; ++d) {
      off = std::max(off, std::abs(x[d] - mesh.nodes[v][d]));
      size = std::max(size, std::abs(x[d]));
    }
    if (off > 1e-9 * std::max(size, 1.0)) mesh.nodes[v] = x;
  }
}

}  // namespace

long pyramids_ccx_refuses(const MixedMesh& mesh) {
  const std::vector<char> mask = pyramids_ccx_refuses_mask(mesh);
  return static_cast<long>(mask.size() - std::count(mask.begin(), mask.end(), 0));
}

std::vector<char> pyramids_ccx_refuses_mask(const MixedMesh& mesh) {
  std::vector<char> mask;
  if (mesh.order != 2) return mask;
  // C3D20's 3x3x3 Gauss points, and C3D20R's 2x2x2.
  static const ReferenceElement full = tabulate(CellKind::Hex8, 2, hex20_rule());
  static const ReferenceElement reduced = tabulate(CellKind::Hex8, 2, hex8_rule());
  const auto& hex_edges = edges_of(CellKind::Hex8);
  const auto& pyr_edges = edges_of(CellKind::Pyramid5);
  for (std::size_t c = 0; c < mesh.num_cells(); ++c) {
    if (mesh.cell_kind[c] != CellKind::Pyramid5) continue;
    const std::int32_t* v = mesh.cell(c);
    const std::int32_t* mid = mesh.cell_edges(c);
    // Hex corners 0-3 are the base, 4-7 the apex; a hex edge's node is the pyramid's on the
    // same edge, the apex on the collapsed top face.
    auto corner = [&](int i) { return i < 4 ? i : 4; };
    Vec3 x[20];
    for (int i = 0; i < 8; ++i) x[i] = mesh.nodes[v[corner(i)]];
    for (int e = 0; e < 12; ++e) {
      const int a = corner(hex_edges[e][0]), b = corner(hex_edges[e][1]);
      x[8 + e] = mesh.nodes[v[4]];
      for (int k = 0; k < num_edges(CellKind::Pyramid5) && a != b; ++k)
        if ((pyr_edges[k][0] == a && pyr_edges[k][1] == b) ||
            (pyr_edges[k][0] == b && pyr_edges[k][1] == a))
          x[8 + e] = mesh.nodes[mid[k]];
    }
    if (min_det(full, x) > 0) continue;
    if (mask.empty()) mask.assign(mesh.num_cells(), 0);
    mask[c] = min_det(reduced, x) > 0 ? 1 : 2;
  }
  return mask;
}

std::string ccx_pyramid_warning(const std::vector<char>& mask, const std::filesystem::path& inp) {
  const long n = static_cast<long>(mask.size() - std::count(mask.begin(), mask.end(), 0));
  if (n == 0) return "";
  const long still = static_cast<long>(std::count(mask.begin(), mask.end(), 2));
  return std::to_string(n) + " pyramid(s) in " + inp.string() +
         " are written as C3D20R (reduced integration): as CalculiX's collapsed C3D20 they are "
         "inside out at its integration points, although hexfem's pyramid13 is valid" +
         (still ? " (" + std::to_string(still) +
                      " of them at C3D20R's points too: ccx will refuse the file)"
                : "") +
         "; --no-pyramids meshes without pyramids";
}

std::filesystem::path ccx_deck_mesh_path(const std::filesystem::path& deck) {
  std::filesystem::path mesh_file = deck;
  return mesh_file.replace_filename(deck.stem().string() + "_mesh.inp");
}

long straighten_for_ccx(MixedMesh& mesh, const std::vector<char>& mask) {
  long n = 0;
  const auto& edges = edges_of(CellKind::Pyramid5);
  for (std::size_t c = 0; c < mask.size(); ++c) {
    if (mask[c] != 2) continue;
    const std::int32_t* v = mesh.cell(c);
    const std::int32_t* mid = mesh.cell_edges(c);
    for (int e = 0; e < num_edges(CellKind::Pyramid5); ++e) {
      const Vec3 &a = mesh.nodes[v[edges[e][0]]], &b = mesh.nodes[v[edges[e][1]]];
      mesh.nodes[mid[e]] = {0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1]), 0.5 * (a[2] + b[2])};
    }
    ++n;
  }
  return n;
}

CcxDeckFiles write_ccx_deck(const MixedMesh& mesh, const ModalOptions& options,
                            const std::vector<std::uint8_t>& fixed,
                            const std::filesystem::path& deck) {
  const std::filesystem::path mesh_file = ccx_deck_mesh_path(deck);
  // A pyramid inside out at C3D20R's points too would make ccx refuse the whole deck: its
  // mid-edge nodes go to their edges' middles in the deck (the neighbours on those edges follow),
  // where the collapsed C3D20 is valid. The deck then checks a model a few edges straighter.
  MixedMesh deck_mesh = mesh;
  std::vector<char> reduced = pyramids_ccx_refuses_mask(mesh);
  const long straightened = straighten_for_ccx(deck_mesh, reduced);
  // The ties are hexfem's (weights of the curved faces); a hanging node whose masters moved goes
  // where its tie puts it, or the tie would not carry a rigid rotation (AS1 free-free: three
  // rigid-body modes at 40-62 Hz in ccx, from 9 ties of 1367).
  const NodeTies ties = nc_face_ties(mesh, fixed);
  if (straightened > 0) {
    follow_ties(deck_mesh, ties);
    reduced = pyramids_ccx_refuses_mask(deck_mesh);
  }
  write_inp(deck_mesh, mesh_file, node_tie_list(ties), mesh.order == 1 && options.incompatible_hex,
            reduced);

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
          << inp_real(m.E * E_scale) << ", " << inp_real(m.nu) << "\n*DENSITY\n"
          << inp_real(m.rho * rho_scale) << "\n*SOLID SECTION, ELSET=SOLID_" << solid
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
  std::string warning = ccx_pyramid_warning(reduced, mesh_file);
  if (straightened > 0)
    warning += (warning.empty() ? "" : "; ") + std::to_string(straightened) +
               " pyramid(s) inside out at C3D20R's points too are straight in " +
               mesh_file.string() +
               " (their mid-edge nodes at their edges' middles, so ccx can read the deck)";
  if (ties.refused > 0)
    warning += (warning.empty() ? "" : "; ") + std::to_string(ties.refused) +
               " order-2 hanging nodes of NC faces are untied in " + mesh_file.string() +
               " as in hexfem's own solve (nested, fixed or off their face; --conformal leaves "
               "none)";
  return {deck, mesh_file, warning};
}

}  // namespace hexfem
