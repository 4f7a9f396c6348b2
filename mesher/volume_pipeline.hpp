// The volume mesher, end to end: surface mesh -> 3D frame field -> frontal points -> TetGen ->
// hexes -> prisms -> pyramids -> mixed mesh with boundary quads and NC flags.
//
// Takes: a closed SurfaceMesh and VolumeOptions.
// Gives: the hex-dominant MixedMesh with boundary faces and NC flags, and a VolumeReport.
// Keeps: each TetGen tet in exactly one place (verified before assembly); deterministic for any
// thread count.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "mesher/conformal.hpp"
#include "mesher/mesh/mesh_stats.hpp"
#include "mesher/mesh/mixed_mesh.hpp"
#include "mesher/recombine_select.hpp"
#include "mesher/stage_timer.hpp"
#include "mesher/surface_mesh.hpp"
#include "mesher/tetrahedralize.hpp"
#include "mesher/volume_points.hpp"
#include "mesher/volume_points_lpcvt.hpp"

namespace hexfem {

struct VolumeOptions {
  double k = 0.7;              // exclusion factor of the point insertion (--k), in (0, 1)
  double min_quality = 0.3;    // hexes/prisms below this min scaled Jacobian are not made
  bool no_prisms = false;      // --no-prisms
  bool no_pyramids = false;    // --no-pyramids
  bool random_points = false;  // --random-points: random interior points at the same density
  std::uint64_t random_seed = 1;
  // An element may differ from its tets' volume by this fraction (the net bulge of its
  // non-planar quad faces, never more than max_face_twist). 0.1 rather than 0.02: ANC101
  // h = 4.5 H_vol +5.7 points, H_nbr +13.5, more hexes on every shared part; the global volume
  // gap stays bounded by max_total_gap (the elements losing most go back to tets).
  double max_volume_gap = 0.1;
  double max_face_twist = 0.2;  // quad faces' distance from planar (FillRules)
  double jitter = 0;            // interior points moved by up to jitter*h (volume_points.hpp)
  bool inherit_frame = true;    // points take their front's frame (volume_points.hpp)
  bool smooth_frame = false;    // --smooth-frame: the smooth field's frame (frame_field_smooth.hpp)
  // Coherent fronts first (volume_points.hpp); --no-coherent-first: every front at once (paper).
  bool coherent_first = true;
  CoherentWalls coherent;  // --coherent-axes N, --coherent-share S (study switches)
  // --relax-points N: lattice relaxation sweeps (volume_points.hpp); 30 by default since session
  // 29 (volume.md, "Relaxation and edge spacing by default"), 0 = off.
  int relax_points = 30;
  int lp_cvt = 0;    // --lp-cvt N: Lp-CVT iterations (volume_points_lpcvt.hpp)
  int lp_cvt_p = 8;  // --lp-cvt-p P: its exponent
  // --tetgen-delaunay-recovery: TetGen's Delaunay recovery after the boundary recovery
  // (tetrahedralize.hpp). Off: ANC101 at 1M vertices TetGen 38 -> 15 s, H_nbr 80.78 -> 80.77 %.
  bool tetgen_delaunay_recovery = false;
  // A free tet on an element's quad face with a lower min scaled Jacobian is merged into that
  // element (a sliver between the face's two diagonals).
  double flat_tet_quality = 0.02;
  double min_pyramid_quality = 0.05;  // pyramids with a lower min scaled Jacobian stay two tets
  // An element goes back to tets (NC repair, volume gap) only when each tet it gives back has at
  // least this min scaled Jacobian; a tet this flat next to a pyramid makes the pyramid go.
  double keep_tet_quality = 1e-3;
  // |V(mixed) - V(tets)| / V(tets) allowed: elements whose unshared twisted quad faces lose the
  // most volume go back to tets until it holds (volume_gap.hpp; --max-gap).
  double max_total_gap = 8e-4;
  // Elements that make more NC quad faces than they match go back to tets; a hex only when
  // that removes at least nc_hex_gain NC faces (recombine_conformity.hpp). 2 rather than 1:
  // ANC101 h = 4.5 NC 4.68 vs 4.44 %, H_vol 88.22 vs 87.92 %; Laufrad h = 64 H_vol 46.0 vs 40.3 %
  // (measured before the gain counted the pyramids made on the partners' faces). The stage
  // also fills wedge gaps between elements with prisms. --no-nc-repair turns it off for studies.
  bool nc_repair = true;
  int nc_hex_gain = 2;
  // --conformal: after assembly, every NC quad made conformal with real elements (conformal.hpp).
  bool conformal = false;
  // --hex-selection: the paper's greedy best-first pass alone, or followed by 1-for-k swaps on
  // the candidates' conflict graph (recombine_select.hpp). Swaps by default since session 32,
  // when their pool became the candidates holding a free tet (ANC101 h = 4.5: H_nbr 77.04 ->
  // 78.84 %, 1M vertices +3 s); on the wide search's pool since session 33, when its tests moved
  // to where the candidates are found (80.01 %, 1M vertices 46 s against 40 s;
  // validation/volume.md).
  HexSelection hex_selection = HexSelection::kSwapWide;
};

struct VolumeReport {
  std::size_t surface_vertices = 0, interior_points = 0, steiner_points = 0;
  LpCvtReport lp_cvt;                // --lp-cvt: the optimisation's energies and iterations
  double tetgen_seconds = 0;         // TetGen's own run, inside the "tetgen" stage (TetMesh)
  std::size_t frontal_points = 0;    // random mode: the frontal count it aimed at
  std::size_t tets = 0;              // TetGen's tets (inside the solids)
  std::size_t absorbed_slivers = 0;  // flat tets on a hex/prism quad face, merged into it
  std::size_t tets_in_elements = 0;  // tets merged into hexes, prisms and pyramids
  // Edge-removal flips of the slivers left (volume_slivers.hpp): TetGen tets replaced and the
  // tets replacing them; slivers_left: free tets still below flat_tet_quality.
  std::size_t sliver_flips = 0, flipped_tets = 0, tets_from_flips = 0, slivers_left = 0;
  // Flat tets on the surface dropped right after TetGen (volume_slivers.hpp): TetGen's tets =
  // these + tets in elements + absorbed slivers + flipped tets + tets left.
  std::size_t flat_boundary_tets = 0;
  // Slivers left at the end, improved by moving one interior vertex (lift_slivers).
  std::size_t lifted_cells = 0;
  std::size_t dissolved_pyramids = 0;  // pyramids (and prisms) by slivers turned back into tets
  // Elements at the edges of a flat tet turned back into tets when the first try left a flat
  // cell (the flat-cell fallback; 0 when it did not run).
  std::size_t flat_fallback_undone = 0;
  // Interior points added beside flat tets that survived the fallback, for a second (third) run
  // of the whole pipeline (points_beside_flat_tets; 0 when it did not run).
  std::size_t flat_retry_points = 0;
  std::size_t hex_candidates = 0, prism_candidates = 0, pyramid_candidates = 0;
  SwapReport hex_swaps;  // --hex-selection swap: what the swaps did (zeros without)
  std::size_t boundary_triangles = 0, boundary_quads = 0;
  // gap = |V(mixed) - V(tets)| / V(tets), V(mixed) = stats.volume.
  double volume_tets = 0, volume_rel_gap = 0;
  // Sum over elements of V(element) - V(its tets), and V(absorbed slivers): the mixed volume
  // is V(tets) + the first - the second + what elements' bilinear faces add around slivers.
  double volume_elements_gap = 0, volume_absorbed = 0;
  // The gap before the elements losing most were undone (volume_gap.hpp), and how many were.
  double volume_gap_before = 0;
  std::array<std::size_t, kNumCellKinds> gap_undone{};
  // NC quad faces of the elements before and after the NC repair, what it undid and the
  // pyramids it made on the faces left (recombine_conformity.hpp).
  std::size_t nc_faces_before_repair = 0, nc_faces_after_repair = 0, nc_repair_pyramids = 0;
  std::size_t nc_repair_prisms = 0;  // prisms made in gaps between elements
  std::array<std::size_t, kNumCellKinds> nc_undone{};
  // What the conformal pass did (--conformal; zeros without it).
  ConformalReport conformal;
  // The mesh returned: vertices, cells per kind, H_nbr, H_vol, Q, NC, inverted, volume.
  MeshStats stats;
  std::vector<StageTime> stages;
  double total_seconds = 0, total_cpu_seconds = 0;
  int threads = 1;
};

// Throws hexfem::Error (one line) for a bad surface mesh or option, or when TetGen fails.
MixedMesh mesh_volume(const SurfaceMesh& surface, const VolumeOptions& options = {},
                      VolumeReport* report = nullptr);

// The recombination alone, on tets made elsewhere (`hexfem recombine`: another mesher's tets,
// to compare recombinations on the same tets): the stages after TetGen, as mesh_volume runs
// them. `surface` holds the tets' boundary (and interface) triangles on the first nodes of
// `tets`, with outward normals. The report's point and TetGen figures stay zero.
MixedMesh recombine_tets(TetMesh tets, const SurfaceMesh& surface,
                         const VolumeOptions& options = {}, VolumeReport* report = nullptr);

}  // namespace hexfem
