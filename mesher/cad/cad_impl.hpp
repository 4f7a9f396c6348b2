// Private to mesher/cad/*.cpp: the OpenCASCADE side of CadModel. Never include elsewhere.
#pragma once

#include <BRepTopAdaptor_FClass2d.hxx>
#include <Geom2d_Curve.hxx>
#include <Geom_Curve.hxx>
#include <Geom_Surface.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Shape.hxx>
#include <TopoDS_Solid.hxx>
#include <filesystem>
#include <gp_Pnt.hxx>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "mesher/cad/cad_model.hpp"

namespace hexfem {

inline Vec3 to_vec(const gp_Pnt& p) {
  return {p.X(), p.Y(), p.Z()};
}
inline Vec3 to_vec(const gp_Vec& v) {
  return {v.X(), v.Y(), v.Z()};
}

struct EdgeData {
  TopoDS_Edge edge;          // FORWARD
  Handle(Geom_Curve) curve;  // location applied; null for a degenerate edge
  double first = 0, last = 0;
  bool degenerate = false;
  std::array<int, 2> vertices{0, 0};
  double length = 0;
  std::vector<int> faces;
};

struct CoEdgeData {
  TopoDS_Edge edge;  // oriented as in the face's wire
  Handle(Geom2d_Curve) pcurve;
};

struct FaceData {
  TopoDS_Face face;              // oriented as in its (first) solid
  Handle(Geom_Surface) surface;  // location applied
  SurfaceType type = SurfaceType::Other;
  std::array<double, 4> bounds{0, 0, 0, 0};
  Vec2 periods{0, 0};
  bool reversed = false;
  std::vector<CoEdge> coedges;
  std::vector<CoEdgeData> coedge_data;
  double area = 0;
  Vec3 centroid{0, 0, 0};
  std::vector<int> solids;
  // The trimmed-domain classifier is built on first use (it costs a polygonisation of the
  // boundary); the once_flag makes that safe when faces are meshed in parallel.
  mutable std::unique_ptr<std::once_flag> classifier_once = std::make_unique<std::once_flag>();
  mutable std::unique_ptr<BRepTopAdaptor_FClass2d> classifier;
};

struct SolidData {
  TopoDS_Solid solid;
  std::vector<int> faces;
  double volume = 0;
};

struct CadModel::Impl {
  std::string format;
  std::string file_unit;
  double unit_scale = 1.0;
  std::vector<std::string> warnings;
  TopoDS_Shape part;  // compound of the solids
  TopTools_IndexedMapOfShape vertex_map, edge_map, face_map, solid_map;
  std::vector<gp_Pnt> vertices;  // index = id - 1
  std::vector<double> vertex_tol;
  std::vector<EdgeData> edges;
  std::vector<FaceData> faces;
  std::vector<SolidData> solids;
  double volume = 0, area = 0;
  // Bounding boxes are exact (BRepBndLib::AddOptimal), which costs seconds on parts with many
  // tori and B-splines: computed on first use (only `hexfem info` and studies ask).
  mutable std::mutex bbox_mutex;
  mutable std::vector<std::optional<BBox3>> face_bbox, solid_bbox;
  mutable std::optional<BBox3> part_bbox;

  // Fills every table from `part` (a compound of correctly oriented solids).
  void build_tables();
};

BBox3 shape_bbox(const TopoDS_Shape& shape);

std::string lower_case(std::string s);
// Millimetres per unit for the unit names STEP and IGES files use; 0 for an unknown name.
double mm_per_unit(const std::string& name);

// Reads an IGES file in a forked child (iges_read.cpp); records the file's unit in `m`.
TopoDS_Shape read_iges(const std::filesystem::path& path, CadModel::Impl& m);

}  // namespace hexfem
