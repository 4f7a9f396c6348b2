// Geometric queries of CadModel: points and derivatives on edges and faces, curvature,
// projection, the trimmed-domain test. All const and safe to call from several threads.
#include <BRep_Tool.hxx>
#include <Extrema_GenLocateExtPS.hxx>
#include <Extrema_POnSurf.hxx>
#include <GeomAPI_ProjectPointOnSurf.hxx>
#include <GeomAdaptor_Surface.hxx>
#include <GeomLProp_CLProps.hxx>
#include <GeomLProp_SLProps.hxx>
#include <Standard_Failure.hxx>
#include <TopoDS.hxx>
#include <algorithm>
#include <cmath>
#include <gp_Pnt2d.hxx>

#include "mesher/cad/cad_impl.hpp"
#include "mesher/mesh/error.hpp"

namespace hexfem {

const char* surface_type_name(SurfaceType type) {
  switch (type) {
    case SurfaceType::Plane:
      return "plane";
    case SurfaceType::Cylinder:
      return "cylinder";
    case SurfaceType::Cone:
      return "cone";
    case SurfaceType::Sphere:
      return "sphere";
    case SurfaceType::Torus:
      return "torus";
    case SurfaceType::Bezier:
      return "bezier";
    case SurfaceType::BSpline:
      return "bspline";
    case SurfaceType::Revolution:
      return "revolution";
    case SurfaceType::Extrusion:
      return "extrusion";
    case SurfaceType::Offset:
      return "offset";
    case SurfaceType::Other:
      return "other";
  }
  return "other";
}

namespace {
template <class T>
const T& at(const std::vector<T>& v, int id, const char* what) {
  if (id < 1 || id > static_cast<int>(v.size()))
    throw Error(std::string("no ") + what + " with id " + std::to_string(id));
  return v[static_cast<std::size_t>(id - 1)];
}
}  // namespace

Vec3 CadModel::vertex_point(int v) const {
  return to_vec(at(impl_->vertices, v, "vertex"));
}
double CadModel::vertex_tolerance(int v) const {
  return at(impl_->vertex_tol, v, "vertex");
}

bool CadModel::edge_degenerate(int e) const {
  return at(impl_->edges, e, "edge").degenerate;
}
bool CadModel::edge_closed(int e) const {
  const auto& d = at(impl_->edges, e, "edge");
  return d.vertices[0] == d.vertices[1];
}
Vec2 CadModel::edge_range(int e) const {
  const auto& d = at(impl_->edges, e, "edge");
  return {d.first, d.last};
}
std::array<int, 2> CadModel::edge_vertices(int e) const {
  return at(impl_->edges, e, "edge").vertices;
}
double CadModel::edge_length(int e) const {
  return at(impl_->edges, e, "edge").length;
}
const std::vector<int>& CadModel::faces_of_edge(int e) const {
  return at(impl_->edges, e, "edge").faces;
}

Vec3 CadModel::edge_point(int e, double t) const {
  const auto& d = at(impl_->edges, e, "edge");
  if (d.degenerate) return vertex_point(d.vertices[0]);
  return to_vec(d.curve->Value(t));
}

Vec3 CadModel::edge_derivative(int e, double t) const {
  const auto& d = at(impl_->edges, e, "edge");
  if (d.degenerate) return {0, 0, 0};
  gp_Pnt p;
  gp_Vec v;
  d.curve->D1(t, p, v);
  return to_vec(v);
}

double CadModel::edge_curvature(int e, double t) const {
  const auto& d = at(impl_->edges, e, "edge");
  if (d.degenerate) return 0;
  try {
    GeomLProp_CLProps props(d.curve, t, 2, 1e-9);
    if (!props.IsTangentDefined()) return 0;
    return std::abs(props.Curvature());
  } catch (const Standard_Failure&) {
    return 0;
  }
}

SurfaceType CadModel::surface_type(int f) const {
  return at(impl_->faces, f, "face").type;
}
std::array<double, 4> CadModel::uv_bounds(int f) const {
  return at(impl_->faces, f, "face").bounds;
}
Vec2 CadModel::periods(int f) const {
  return at(impl_->faces, f, "face").periods;
}
bool CadModel::face_reversed(int f) const {
  return at(impl_->faces, f, "face").reversed;
}
const std::vector<CoEdge>& CadModel::coedges(int f) const {
  return at(impl_->faces, f, "face").coedges;
}
double CadModel::face_area(int f) const {
  return at(impl_->faces, f, "face").area;
}
Vec3 CadModel::face_centroid(int f) const {
  return at(impl_->faces, f, "face").centroid;
}
BBox3 CadModel::face_bbox(int f) const {
  const auto& d = at(impl_->faces, f, "face");
  const auto k = static_cast<std::size_t>(f - 1);
  {
    std::lock_guard lock(impl_->bbox_mutex);
    if (impl_->face_bbox[k]) return *impl_->face_bbox[k];
  }
  const BBox3 b = shape_bbox(d.face);  // outside the lock: faces on several threads at once
  std::lock_guard lock(impl_->bbox_mutex);
  impl_->face_bbox[k] = b;
  return b;
}
void CadModel::compute_face_boxes() const {
  const int n = num_faces();
#pragma omp parallel for schedule(dynamic, 1)
  for (int f = 1; f <= n; ++f) {
    try {
      face_bbox(f);
    } catch (...) {  // face_bbox(f) asked again, on one thread, reports it
    }
  }
}
const std::vector<int>& CadModel::solids_of_face(int f) const {
  return at(impl_->faces, f, "face").solids;
}

namespace {

// Runs an evaluation of face f's surface at uv. OpenCASCADE throws (Standard_OutOfRange in
// Geom_BSplineSurface::D0) for some surfaces at parameters just outside their knot range, which
// the packing and the edge walks reach; the point is then taken at uv clamped to the surface's
// own bounds, and anything else becomes a one-line hexfem::Error naming the face.
template <class Eval>
auto evaluate(const FaceData& d, int f, Vec2 uv, Eval eval) {
  try {
    return eval(uv);
  } catch (const Standard_Failure&) {
  }
  double u1 = 0, u2 = 0, v1 = 0, v2 = 0;
  d.surface->Bounds(u1, u2, v1, v2);
  const Vec2 clamped{std::clamp(uv[0], u1, u2), std::clamp(uv[1], v1, v2)};
  try {
    return eval(clamped);
  } catch (const Standard_Failure& e) {
    throw Error("face " + std::to_string(f) + ": OpenCASCADE cannot evaluate its surface at (" +
                std::to_string(uv[0]) + ", " + std::to_string(uv[1]) +
                "): " + e.GetMessageString());
  }
}

}  // namespace

SurfaceDerivs CadModel::eval(int f, Vec2 uv) const {
  const auto& d = at(impl_->faces, f, "face");
  return evaluate(d, f, uv, [&](Vec2 q) {
    gp_Pnt p;
    gp_Vec du, dv;
    d.surface->D1(q[0], q[1], p, du, dv);
    return SurfaceDerivs{to_vec(p), to_vec(du), to_vec(dv)};
  });
}

Vec3 CadModel::point(int f, Vec2 uv) const {
  const auto& d = at(impl_->faces, f, "face");
  return evaluate(d, f, uv, [&](Vec2 q) { return to_vec(d.surface->Value(q[0], q[1])); });
}

Vec3 CadModel::normal(int f, Vec2 uv) const {
  const auto& d = at(impl_->faces, f, "face");
  return evaluate(d, f, uv, [&](Vec2 q) -> Vec3 {
    gp_Pnt p;
    gp_Vec du, dv;
    d.surface->D1(q[0], q[1], p, du, dv);
    gp_Vec n = du.Crossed(dv);
    const double len = n.Magnitude();
    if (len < 1e-300) {
      // Singular point (pole, apex): the curvature-based normal from the second derivatives.
      GeomLProp_SLProps props(d.surface, q[0], q[1], 1, 1e-9);
      if (!props.IsNormalDefined()) return {0, 0, 0};
      gp_Dir nd = props.Normal();
      if (d.reversed) nd.Reverse();
      return {nd.X(), nd.Y(), nd.Z()};
    }
    n /= len;
    if (d.reversed) n.Reverse();
    return to_vec(n);
  });
}

double CadModel::max_curvature(int f, Vec2 uv) const {
  const auto& d = at(impl_->faces, f, "face");
  if (d.type == SurfaceType::Plane) return 0;
  try {
    GeomLProp_SLProps props(d.surface, uv[0], uv[1], 2, 1e-9);
    if (!props.IsCurvatureDefined()) return 0;
    return std::max(std::abs(props.MaxCurvature()), std::abs(props.MinCurvature()));
  } catch (const Standard_Failure&) {
    return 0;
  }
}

Vec2 CadModel::project(int f, const Vec3& p) const {
  const auto& d = at(impl_->faces, f, "face");
  try {
    GeomAPI_ProjectPointOnSurf proj(gp_Pnt(p[0], p[1], p[2]), d.surface, d.bounds[0], d.bounds[1],
                                    d.bounds[2], d.bounds[3]);
    if (proj.NbPoints() > 0) {
      double u = 0, v = 0;
      proj.LowerDistanceParameters(u, v);
      return {u, v};
    }
  } catch (const Standard_Failure&) {
  }
  throw Error("face " + std::to_string(f) + ": cannot project a point onto its surface");
}

struct FaceProjector::Impl {
  GeomAdaptor_Surface surface;
  std::unique_ptr<Extrema_GenLocateExtPS> locate;
};

FaceProjector::FaceProjector(const CadModel& cad, int f) : impl_(std::make_unique<Impl>()) {
  const auto& d = at(cad.impl().faces, f, "face");
  try {
    impl_->surface.Load(d.surface, d.bounds[0], d.bounds[1], d.bounds[2], d.bounds[3]);
    impl_->locate = std::make_unique<Extrema_GenLocateExtPS>(impl_->surface);
  } catch (const Standard_Failure&) {
    impl_->locate.reset();
  }
}

FaceProjector::~FaceProjector() = default;

bool FaceProjector::project(const Vec3& p, Vec2 start, Vec2& uv) {
  if (!impl_->locate) return false;
  try {
    impl_->locate->Perform(gp_Pnt(p[0], p[1], p[2]), start[0], start[1], Standard_True);
    if (!impl_->locate->IsDone()) return false;
    impl_->locate->Point().Parameter(uv[0], uv[1]);
    return std::isfinite(uv[0]) && std::isfinite(uv[1]);
  } catch (const Standard_Failure&) {
    return false;
  }
}

bool CadModel::contains(int f, Vec2 uv) const {
  const auto& d = at(impl_->faces, f, "face");
  std::call_once(*d.classifier_once, [&d] {
    d.classifier = std::make_unique<BRepTopAdaptor_FClass2d>(
        TopoDS::Face(d.face.Oriented(TopAbs_FORWARD)), BRep_Tool::Tolerance(d.face));
  });
  // No periodic wrapping: a point past the seam is outside, the other side of the seam is
  // filled from its own copy of the seam points.
  return d.classifier->Perform(gp_Pnt2d(uv[0], uv[1]), false) != TopAbs_OUT;
}

Vec2 CadModel::coedge_uv(int f, int c, double t) const {
  const auto& d = at(impl_->faces, f, "face");
  const gp_Pnt2d p = d.coedge_data.at(static_cast<std::size_t>(c)).pcurve->Value(t);
  return {p.X(), p.Y()};
}

}  // namespace hexfem
