#include "mesher/mesh/conformity.hpp"

#include "mesher/mesh/face_keys.hpp"
#include "mesher/mesh/parallel.hpp"

namespace hexfem {

std::vector<CellFaceRef> sorted_cell_faces(const MixedMesh& mesh) {
  // Each cell's faces in its own slots (on all threads), then one sort: the order is total, so
  // the list does not depend on the threads.
  const std::size_t nc = mesh.num_cells();
  std::vector<std::size_t> off(nc + 1, 0);
  for (std::size_t c = 0; c < nc; ++c) off[c + 1] = off[c] + faces_of(mesh.cell_kind[c]).count;
  std::vector<CellFaceRef> faces(off.back());
  const auto n = static_cast<std::ptrdiff_t>(nc);
#pragma omp parallel for schedule(static, 4096)
  for (std::ptrdiff_t c = 0; c < n; ++c) {
    const CellFaces cf = faces_of(mesh.cell_kind[c]);
    for (int f = 0; f < cf.count; ++f)
      faces[off[c] + f] = {face_key(mesh.cell(c), cf.face[f]), static_cast<std::int32_t>(c),
                           static_cast<std::int8_t>(f)};
  }
  parallel_sort(faces);
  return faces;
}

bool face_used_by_other_cell(const std::vector<CellFaceRef>& faces, const FaceKey& key,
                             std::int32_t cell) {
  auto it = std::lower_bound(faces.begin(), faces.end(), CellFaceRef{key, -1, -1});
  for (; it != faces.end() && it->key == key; ++it)
    if (it->cell != cell) return true;
  return false;
}

namespace {

// A quad face that no other quad matches is non-conformal when another cell has a triangle
// face on three of its four corners (it is then interior, just split); otherwise it is boundary.
bool quad_touches_triangles(const std::vector<CellFaceRef>& faces, const FaceKey& quad,
                            std::int32_t cell) {
  for (int skip = 0; skip < 4; ++skip) {
    std::int32_t t[3];
    int n = 0;
    for (int i = 0; i < 4; ++i)
      if (i != skip) t[n++] = quad[i];
    if (face_used_by_other_cell(faces, triangle_key(t[0], t[1], t[2]), cell)) return true;
  }
  return false;
}

template <class Visit>
void for_each_interior_quad(const std::vector<CellFaceRef>& faces, Visit visit) {
  for (std::size_t i = 0; i < faces.size();) {
    std::size_t j = i;
    while (j < faces.size() && faces[j].key == faces[i].key) ++j;
    if (faces[i].key[0] >= 0) {  // a quad
      if (j - i >= 2) {
        visit(faces[i], /*matched=*/true);
      } else if (quad_touches_triangles(faces, faces[i].key, faces[i].cell)) {
        visit(faces[i], /*matched=*/false);
      }
    }
    i = j;
  }
}

}  // namespace

void flag_nonconformal_quads(MixedMesh& mesh, const std::vector<CellFaceRef>& faces) {
  mesh.nc_cell.clear();
  mesh.nc_local_face.clear();
  for_each_interior_quad(faces, [&](const CellFaceRef& f, bool matched) {
    if (matched) return;
    mesh.nc_cell.push_back(f.cell);
    mesh.nc_local_face.push_back(f.local);
  });
}

void flag_nonconformal_quads(MixedMesh& mesh) {
  flag_nonconformal_quads(mesh, sorted_cell_faces(mesh));
}

QuadFaceCounts count_quad_faces(const std::vector<CellFaceRef>& faces) {
  QuadFaceCounts counts;
  for_each_interior_quad(faces, [&](const CellFaceRef&, bool matched) {
    ++counts.interior;
    if (!matched) ++counts.nonconformal;
  });
  return counts;
}

QuadFaceCounts count_quad_faces(const MixedMesh& mesh) {
  return count_quad_faces(sorted_cell_faces(mesh));
}

}  // namespace hexfem
