#include "mesher/mesh/mesh_stats.hpp"

#include <algorithm>
#include <cstdio>
#include <future>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <string>

#include "mesher/mesh/conformity.hpp"
#include "mesher/mesh/face_keys.hpp"
#include "mesher/mesh/quality.hpp"

namespace hexfem {

namespace {

// Faces of the boundary of the cell complex: cell faces that no other cell shares, minus the
// interior NC quads and the triangles that meet them.
std::vector<FaceKey> derived_boundary_faces(const MixedMesh& mesh,
                                            const std::vector<CellFaceRef>& faces,
                                            std::vector<const CellFaceRef*>& refs) {
  std::vector<FaceKey> nc_quads;
  for (std::size_t i = 0; i < mesh.nc_cell.size(); ++i) {
    const auto c = mesh.nc_cell[i];
    nc_quads.push_back(
        face_key(mesh.cell(c), faces_of(mesh.cell_kind[c]).face[mesh.nc_local_face[i]]));
  }
  std::sort(nc_quads.begin(), nc_quads.end());
  // Triangles covering NC quads: any triangle on three corners of an NC quad.
  std::vector<FaceKey> nc_tris;
  for (const FaceKey& q : nc_quads)
    for (int skip = 0; skip < 4; ++skip) {
      std::int32_t t[3];
      int n = 0;
      for (int i = 0; i < 4; ++i)
        if (i != skip) t[n++] = q[i];
      nc_tris.push_back(triangle_key(t[0], t[1], t[2]));
    }
  std::sort(nc_tris.begin(), nc_tris.end());

  std::vector<FaceKey> boundary;
  for (std::size_t i = 0; i < faces.size();) {
    std::size_t j = i;
    while (j < faces.size() && faces[j].key == faces[i].key) ++j;
    const FaceKey& k = faces[i].key;
    const bool is_quad = k[0] >= 0;
    const bool nc = is_quad ? std::binary_search(nc_quads.begin(), nc_quads.end(), k)
                            : std::binary_search(nc_tris.begin(), nc_tris.end(), k);
    if (j - i == 1 && !nc) {
      boundary.push_back(k);
      refs.push_back(&faces[i]);
    }
    i = j;
  }
  return boundary;
}

}  // namespace

MeshStats compute_stats(const MixedMesh& mesh) {
  return compute_stats(mesh, sorted_cell_faces(mesh));
}

MeshStats compute_stats(const MixedMesh& mesh, const std::vector<CellFaceRef>& faces) {
  // The quad-face counts do not depend on the rest: a second thread.
  std::future<QuadFaceCounts> counts =
      std::async(std::launch::async, [&faces] { return count_quad_faces(faces); });
  MeshStats s;
  s.order = mesh.order;
  s.num_nodes = mesh.nodes.size();
  s.num_cells = mesh.num_cells();
  s.num_boundary_faces = mesh.num_bfaces();
  std::array<double, kNumCellKinds> vol_per_kind{};
  std::array<double, kNumCellKinds> min_sj;
  min_sj.fill(std::numeric_limits<double>::max());
  double q_sum = 0;
  // Each cell's volume and quality on all threads; the sums below run in cell order, so they
  // do not depend on the threads.
  const std::size_t nc = mesh.num_cells();
  std::vector<double> cell_vol(nc), cell_sj(nc);
  std::vector<char> cell_inv(nc);
  const auto n = static_cast<std::ptrdiff_t>(nc);
#pragma omp parallel for schedule(static, 4096)
  for (std::ptrdiff_t c = 0; c < n; ++c) {
    const CellKind kind = mesh.cell_kind[c];
    Vec3 x[kMaxCellNodes];  // read once for the three measures
    for (int i = 0; i < num_nodes(kind); ++i) x[i] = mesh.nodes[mesh.cell(c)[i]];
    cell_vol[c] = volume(kind, x);
    cell_sj[c] = min_scaled_jacobian(kind, x);
    cell_inv[c] = is_inverted(kind, x);
  }
  for (std::size_t c = 0; c < nc; ++c) {
    const int k = static_cast<int>(mesh.cell_kind[c]);
    ++s.cells_per_kind[k];
    const double v = cell_vol[c];
    vol_per_kind[k] += v;
    s.volume += v;
    const double sj = cell_sj[c];
    min_sj[k] = std::min(min_sj[k], sj);
    if (mesh.cell_kind[c] == CellKind::Hex8) q_sum += sj;
    if (cell_inv[c])
      ++s.inverted;
    else if (sj < kDegenerateScaledJacobian)
      ++s.degenerate;
  }
  for (int k = 0; k < kNumCellKinds; ++k)
    s.min_sj_per_kind[k] = s.cells_per_kind[k] ? min_sj[k] : 0.0;
  s.solid_volumes = volume_by_solid(mesh, cell_vol);
  const int hex = static_cast<int>(CellKind::Hex8);
  if (s.num_cells) s.h_nbr = 100.0 * s.cells_per_kind[hex] / s.num_cells;
  if (s.volume > 0) s.h_vol = 100.0 * vol_per_kind[hex] / s.volume;
  if (s.cells_per_kind[hex]) {
    s.q_mean = q_sum / s.cells_per_kind[hex];
    s.q_min = s.min_sj_per_kind[hex];
  }

  // Watertightness of the derived boundary: every edge in an even number of boundary faces (two
  // on a manifold boundary; four where two glued solids touch along an edge, `--glue`), so the
  // boundary closes. Without NC flags, the counts tell whether the mesh needs them.
  QuadFaceCounts qc;
  if (mesh.nc_cell.empty()) qc = counts.get();
  MixedMesh flagged;
  const MixedMesh* m = &mesh;
  if (mesh.nc_cell.empty() && qc.nonconformal > 0) {
    flagged = mesh;
    flag_nonconformal_quads(flagged);
    m = &flagged;
  }
  // The flagged copy has the same cells, hence the same faces.
  std::vector<const CellFaceRef*> refs;
  const std::vector<FaceKey> boundary = derived_boundary_faces(*m, faces, refs);
  s.boundary_faces_derived = boundary.size();
  std::vector<std::pair<std::int32_t, std::int32_t>> edges;
  for (const CellFaceRef* r : refs) {
    const LocalFace& lf = faces_of(m->cell_kind[r->cell]).face[r->local];
    const std::int32_t* ids = m->cell(r->cell);
    for (int i = 0; i < lf.n; ++i) {
      std::int32_t a = ids[lf.v[i]], b = ids[lf.v[(i + 1) % lf.n]];
      edges.emplace_back(std::min(a, b), std::max(a, b));
    }
  }
  std::sort(edges.begin(), edges.end());
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i;
    while (j < edges.size() && edges[j] == edges[i]) ++j;
    if ((j - i) % 2 != 0) ++s.open_boundary_edges;
    i = j;
  }
  s.watertight = s.num_cells > 0 && s.open_boundary_edges == 0;
  if (counts.valid()) qc = counts.get();
  s.interior_quads = qc.interior;
  s.nonconformal_quads = qc.nonconformal;
  if (qc.interior) s.nc_percent = 100.0 * qc.nonconformal / qc.interior;
  return s;
}

std::vector<SolidVolume> volume_by_solid(const MixedMesh& mesh,
                                         const std::vector<double>& cell_volume) {
  std::map<std::int32_t, double> sums;
  for (std::size_t c = 0; c < mesh.num_cells(); ++c) sums[mesh.cell_solid[c]] += cell_volume[c];
  std::vector<SolidVolume> out;
  for (const auto& [solid, v] : sums) out.push_back({solid, v});
  return out;
}

void to_json(nlohmann::json& j, const MeshStats& s) {
  j["order"] = s.order;
  j["nodes"] = s.num_nodes;
  j["cells"] = s.num_cells;
  nlohmann::json per_kind, min_sj;
  for (int k = 0; k < kNumCellKinds; ++k) {
    per_kind[kind_name(static_cast<CellKind>(k))] = s.cells_per_kind[k];
    min_sj[kind_name(static_cast<CellKind>(k))] = s.min_sj_per_kind[k];
  }
  j["cells_per_kind"] = per_kind;
  j["min_scaled_jacobian"] = min_sj;
  j["boundary_faces"] = s.num_boundary_faces;
  j["H_nbr"] = s.h_nbr;
  j["H_vol"] = s.h_vol;
  j["Q_mean"] = s.q_mean;
  j["Q_min"] = s.q_min;
  j["inverted"] = s.inverted;
  j["degenerate"] = s.degenerate;
  j["interior_quads"] = s.interior_quads;
  j["nonconformal_quads"] = s.nonconformal_quads;
  j["NC"] = s.nc_percent;
  j["open_boundary_edges"] = s.open_boundary_edges;
  j["watertight"] = s.watertight;
  j["volume"] = s.volume;
  nlohmann::json solids = nlohmann::json::array();
  for (const SolidVolume& v : s.solid_volumes)
    solids.push_back({{"solid", v.solid}, {"volume", v.volume}});
  j["volume_per_solid"] = solids;
}

std::string stats_to_text(const MeshStats& s) {
  char buf[2048];
  std::snprintf(buf, sizeof buf,
                "nodes            %zu\n"
                "cells            %zu (%s %zu, %s %zu, %s %zu, %s %zu)\n"
                "H_nbr            %.2f %%\n"
                "H_vol            %.2f %%\n"
                "Q (hex mean/min) %.4f / %.4f\n"
                "min scaled Jac.  hex8 %.4g, wedge6 %.4g, pyramid5 %.4g, tet4 %.4g\n"
                "inverted         %zu\n"
                "degenerate       %zu (scaled Jacobian < %g)\n"
                "NC               %.2f %% (%zu of %zu interior quad faces)\n"
                "boundary         %s (%zu faces, %zu open edges)\n"
                "volume           %.10g\n",
                s.num_nodes, s.num_cells, kind_name(CellKind::Hex8, s.order), s.cells_per_kind[3],
                kind_name(CellKind::Wedge6, s.order), s.cells_per_kind[2],
                kind_name(CellKind::Pyramid5, s.order), s.cells_per_kind[1],
                kind_name(CellKind::Tet4, s.order), s.cells_per_kind[0], s.h_nbr, s.h_vol, s.q_mean,
                s.q_min, s.min_sj_per_kind[3], s.min_sj_per_kind[2], s.min_sj_per_kind[1],
                s.min_sj_per_kind[0], s.inverted, s.degenerate, kDegenerateScaledJacobian,
                s.nc_percent, s.nonconformal_quads, s.interior_quads,
                s.watertight ? "watertight" : "NOT watertight", s.boundary_faces_derived,
                s.open_boundary_edges, s.volume);
  std::string out = buf;
  // One solid's volume is the whole's; of several, each (an assembly's bolts' mass).
  if (s.solid_volumes.size() > 1)
    for (const SolidVolume& v : s.solid_volumes) {
      std::snprintf(buf, sizeof buf, "  solid %-9d %.10g\n", v.solid, v.volume);
      out += buf;
    }
  return out;
}

}  // namespace hexfem
