// A CAD part read through OpenCASCADE, behind plain types: the mesher stages never see OCCT
// (its macro `Handle` breaks CGAL). Ids are 1-based and stable: the order of TopExp::MapShapes
// on the part (a compound of its solids), so users can name faces and vertices by id.
// Lengths are in millimetres whatever the file's unit.
#pragma once

#include <array>
#include <cmath>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "mesher/mesh/mixed_mesh.hpp"

namespace hexfem {

using Vec2 = std::array<double, 2>;

struct BBox3 {
  Vec3 min{0, 0, 0};
  Vec3 max{0, 0, 0};
  double diagonal() const { return std::hypot(max[0] - min[0], max[1] - min[1], max[2] - min[2]); }
};

enum class SurfaceType {
  Plane,
  Cylinder,
  Cone,
  Sphere,
  Torus,
  Bezier,
  BSpline,
  Revolution,
  Extrusion,
  Offset,
  Other
};
const char* surface_type_name(SurfaceType type);

// Point and first derivatives of a face's surface at (u, v).
struct SurfaceDerivs {
  Vec3 p{}, du{}, dv{};
};

// One use of an edge in the boundary of a face. A seam edge of a periodic face appears twice
// (once per orientation), each with its own parametric curve.
struct CoEdge {
  int edge = 0;           // edge id
  bool reversed = false;  // the wire runs along the edge against its parametrisation
  int wire = 0;           // index of the wire in the face (0 = outer wire)
  bool seam = false;      // the edge bounds the face on both sides (periodic seam)
};

struct CadReadOptions {
  // Solids that touch or overlap are fragmented so they share faces (a bonded assembly);
  // otherwise such solids are refused when meshed.
  bool glue = false;
};

class CadModel {
 public:
  // Reads STEP (.step/.stp), IGES (.iges/.igs) or OCCT BREP (.brep/.rle). IGES surfaces are
  // sewn into solids. Throws hexfem::Error with a one-line reason on any failure.
  static CadModel read(const std::filesystem::path& path, const CadReadOptions& options = {});

  CadModel(CadModel&&) noexcept;
  CadModel& operator=(CadModel&&) noexcept;
  ~CadModel();

  const std::string& format() const;  // "STEP", "IGES", "BREP"
  // The length unit written in the file ("mm", "inch", "m", ...; "mm (assumed)" for BREP)
  // and the factor it was scaled by to millimetres.
  const std::string& file_unit() const;
  double unit_scale() const;
  // Non-fatal remarks made while reading (sewing, fixed orientations, ignored free faces).
  const std::vector<std::string>& warnings() const;

  int num_vertices() const;
  int num_edges() const;
  int num_faces() const;
  int num_solids() const;

  // --- vertices
  Vec3 vertex_point(int v) const;
  double vertex_tolerance(int v) const;

  // --- edges (parameter t in edge_range; the 3D curve and every pcurve share it)
  bool edge_degenerate(int e) const;  // collapsed to a point (cone apex, sphere pole)
  bool edge_closed(int e) const;      // both ends at the same vertex
  Vec2 edge_range(int e) const;
  std::array<int, 2> edge_vertices(int e) const;  // vertex at t = first, t = last
  Vec3 edge_point(int e, double t) const;
  Vec3 edge_derivative(int e, double t) const;  // dC/dt
  double edge_curvature(int e, double t) const;
  double edge_length(int e) const;
  const std::vector<int>& faces_of_edge(int e) const;

  // --- faces
  SurfaceType surface_type(int f) const;
  // Parametric bounds of the trimmed face: umin, umax, vmin, vmax.
  std::array<double, 4> uv_bounds(int f) const;
  // Period of the surface in u / v (0 when not periodic).
  Vec2 periods(int f) const;
  // True when the outward normal of the face is -(du x dv) (TopAbs_REVERSED in its solid).
  bool face_reversed(int f) const;
  SurfaceDerivs eval(int f, Vec2 uv) const;
  Vec3 point(int f, Vec2 uv) const;
  // Outward unit normal at (u, v) (the orientation in the solid taken into account).
  Vec3 normal(int f, Vec2 uv) const;
  // Largest absolute principal curvature at (u, v) (0 where undefined).
  double max_curvature(int f, Vec2 uv) const;
  // Parameters of the point of the face's surface closest to p.
  Vec2 project(int f, const Vec3& p) const;
  // Whether (u, v) lies inside the trimmed domain of the face (on the boundary counts inside).
  bool contains(int f, Vec2 uv) const;
  const std::vector<CoEdge>& coedges(int f) const;
  // Point of coedge c (index into coedges(f)) in the parameter plane at edge parameter t.
  Vec2 coedge_uv(int f, int c, double t) const;
  double face_area(int f) const;
  Vec3 face_centroid(int f) const;
  BBox3 face_bbox(int f) const;
  // Every face's box made at once on all threads (each is a search on its surface; `hexfem info`
  // lists them all: 0082_MVE's 663 faces).
  void compute_face_boxes() const;
  const std::vector<int>& solids_of_face(int f) const;

  // --- solids and the whole part
  const std::vector<int>& faces_of_solid(int s) const;
  double solid_volume(int s) const;
  BBox3 solid_bbox(int s) const;
  double volume() const;  // sum over solids
  BBox3 bbox() const;
  double area() const;  // sum over the faces of solids

  struct Impl;
  const Impl& impl() const { return *impl_; }

 private:
  explicit CadModel(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// Many projections onto one face from nearby starting parameters: a local search (OCCT's
// Extrema_GenLocateExtPS), where CadModel::project searches a grid over the whole surface at
// every call (most of the cost on a large B-spline face).
class FaceProjector {
 public:
  FaceProjector(const CadModel& cad, int f);
  ~FaceProjector();
  FaceProjector(const FaceProjector&) = delete;
  FaceProjector& operator=(const FaceProjector&) = delete;
  // Parameters of the point of the face's surface nearest p, searched from `start` (the
  // parameters of a point of the face near p); false when the search fails.
  bool project(const Vec3& p, Vec2 start, Vec2& uv);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace hexfem
