// Reading CAD files into CadModel: format detection, units, sewing of surface models into
// solids, stable ids (TopExp::MapShapes order on the compound of solids).
#include <BOPAlgo_Builder.hxx>
#include <BRepAdaptor_Curve.hxx>
#include <BRepAdaptor_Surface.hxx>
#include <BRepBndLib.hxx>
#include <BRepBuilderAPI_Sewing.hxx>
#include <BRepGProp.hxx>
#include <BRepTools.hxx>
#include <BRepTools_WireExplorer.hxx>
#include <BRep_Builder.hxx>
#include <BRep_Tool.hxx>
#include <Bnd_Box.hxx>
#include <GCPnts_AbscissaPoint.hxx>
#include <GProp_GProps.hxx>
#include <Interface_Check.hxx>
#include <Interface_InterfaceModel.hxx>
#include <Interface_Static.hxx>
#include <Message.hxx>
#include <Message_Messenger.hxx>
#include <Message_PrinterOStream.hxx>
#include <STEPControl_Reader.hxx>
#include <ShapeFix_Solid.hxx>
#include <Standard_Failure.hxx>
#include <StepGeom_GeometricRepresentationItem.hxx>
#include <StepShape_TopologicalRepresentationItem.hxx>
#include <TColStd_SequenceOfAsciiString.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>
#include <TopoDS_Shell.hxx>
#include <TopoDS_Wire.hxx>
#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <iterator>
#include <sstream>
#include <streambuf>
#include <utility>

#include "mesher/cad/cad_impl.hpp"
#include "mesher/cad/read_in_child.hpp"
#include "mesher/cad/step_check.hpp"
#include "mesher/mesh/error.hpp"

namespace hexfem {

std::string lower_case(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// Millimetres per unit for the unit names STEP and IGES files use.
double mm_per_unit(const std::string& name) {
  const std::string n = lower_case(name);
  if (n == "mm" || n == "millimetre" || n == "millimeter") return 1.0;
  if (n == "m" || n == "metre" || n == "meter") return 1000.0;
  if (n == "cm" || n == "centimetre" || n == "centimeter") return 10.0;
  if (n == "km") return 1e6;
  if (n == "um" || n == "micron" || n == "micrometre") return 1e-3;
  if (n == "in" || n == "inch" || n == "inches") return 25.4;
  if (n == "ft" || n == "foot" || n == "feet") return 304.8;
  if (n == "mil") return 0.0254;
  if (n == "mi" || n == "mile") return 1609344.0;
  return 0.0;  // unknown
}

namespace {

namespace fs = std::filesystem;

// OCCT prints warnings on stdout by default; hexfem's stdout carries --json output.
void silence_occt() {
  static std::once_flag once;
  std::call_once(once, [] {
    Message::DefaultMessenger()->RemovePrinters(STANDARD_TYPE(Message_PrinterOStream));
  });
}

std::string read_head(const fs::path& path, std::size_t n) {
  std::ifstream in(path, std::ios::binary);
  std::string s(n, '\0');
  in.read(s.data(), static_cast<std::streamsize>(n));
  s.resize(static_cast<std::size_t>(in.gcount()));
  return s;
}

// OpenCASCADE's STEP translator dereferences the null left by a geometric or topological
// entity that failed to parse (found by the fuzz run, issue 14): refuse such a file first.
// Broken styling or unit entities (seen in valid parts) are left to the translator.
void check_step_entities(const fs::path& path, const STEPControl_Reader& reader) {
  const Handle(Interface_InterfaceModel) model = reader.Model();
  for (int i = 1; i <= model->NbEntities(); ++i) {
    if (!model->IsErrorEntity(i)) continue;
    const Handle(Standard_Transient) e = model->Value(i);
    if (!e->IsKind(STANDARD_TYPE(StepGeom_GeometricRepresentationItem)) &&
        !e->IsKind(STANDARD_TYPE(StepShape_TopologicalRepresentationItem)))
      continue;
    const Handle(Interface_Check) check = model->Check(i, true);
    const std::string why = !check.IsNull() && check->NbFails() > 0 ? check->CFail(1) : "";
    throw Error("'" + path.string() + "' is not a readable STEP file: entity " + std::to_string(i) +
                " (" + model->TypeName(e) + ") is corrupt" + (why.empty() ? "" : " (" + why + ")"));
  }
}

// The translation itself (in a child: read_in_child.hpp).
TopoDS_Shape read_step_here(const fs::path& path, CadModel::Impl& m) {
  STEPControl_Reader reader;
  // Convert every length to millimetres on transfer (the unit the mesher works in).
  Interface_Static::SetCVal("xstep.cascade.unit", "MM");
  if (reader.ReadFile(path.string().c_str()) != IFSelect_RetDone)
    throw Error("'" + path.string() + "' is not a readable STEP file (syntax error or truncated)");
  check_step_entities(path, reader);
  TColStd_SequenceOfAsciiString lengths, angles, solid_angles;
  reader.FileUnits(lengths, angles, solid_angles);
  m.file_unit = lengths.IsEmpty() ? std::string("mm (none declared)")
                                  : lower_case(lengths.First().ToCString());
  if (!lengths.IsEmpty()) {
    const double s = mm_per_unit(m.file_unit);
    if (s == 0.0) throw Error("STEP file unit '" + m.file_unit + "' is not supported");
    m.unit_scale = s;
  }
  for (int i = 2; i <= lengths.Length(); ++i)
    if (lower_case(lengths.Value(i).ToCString()) != m.file_unit)
      m.warnings.push_back("the STEP file mixes length units; each was converted to mm");
  if (reader.TransferRoots() == 0 || reader.NbShapes() == 0)
    throw Error("'" + path.string() + "' contains no shape that can be transferred");
  return reader.OneShape();
}

// The header and the entity references are checked here; OpenCASCADE's translator is then tried
// in a child first, since it crashes on some damaged files that pass them (a pcurve naming no
// curve: StepToGeom::MakeCurve2d).
TopoDS_Shape read_step(const fs::path& path, CadModel::Impl& m) {
  const std::string head = read_head(path, 64);
  if (head.find("ISO-10303-21") == std::string::npos)
    throw Error("'" + path.string() + "' is not a STEP file (no ISO-10303-21 header)");
  {
    std::ifstream in(path, std::ios::binary);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::string problem = step_entity_problem(text);
    if (!problem.empty())
      throw Error("'" + path.string() + "' is not a readable STEP file: " + problem);
  }
  return read_in_child(
      path, "STEP", [&](CadModel::Impl& here) { return read_step_here(path, here); }, m,
      ChildRead::kProbe);
}

// Holds std::cout's output while it lives. OCCT's BREP reader writes its complaints about a
// damaged file ("Not a TShape table", "Not a Curve table", ...) straight to std::cout, past the
// Message printers silence_occt removes; hexfem's stdout carries --json output.
class CoutCapture {
 public:
  CoutCapture() : old_(std::cout.rdbuf(text_.rdbuf())) {}
  ~CoutCapture() { std::cout.rdbuf(old_); }
  CoutCapture(const CoutCapture&) = delete;
  CoutCapture& operator=(const CoutCapture&) = delete;

  // What was written, its lines joined by "; " (the error stays one line).
  std::string text() const {
    std::string out;
    std::istringstream in(text_.str());
    for (std::string line; std::getline(in, line);) {
      while (!line.empty() && std::isspace(static_cast<unsigned char>(line.back())))
        line.pop_back();
      if (line.empty()) continue;
      out += (out.empty() ? "" : "; ") + line;
    }
    return out;
  }

 private:
  std::ostringstream text_;
  std::streambuf* old_;
};

// A BREP file's bytes and one newline more, for BRepTools::Read; reading past them throws
// PastTheEnd (through the istream: badbit is in its exceptions mask). On a truncated file the
// reader loops for ever once its stream has failed (BRepTools_ShapeSet::ReadGeometry reads an
// edge's curve records while the last number it read is positive, and a failed read leaves that
// number as it was). A valid file is read up to its last number and the newline after it.
struct PastTheEnd {};
class BrepBytes : public std::streambuf {
 public:
  explicit BrepBytes(std::string bytes) : bytes_(std::move(bytes)) {
    bytes_ += '\n';
    setg(bytes_.data(), bytes_.data(), bytes_.data() + bytes_.size());
  }

 protected:
  int_type underflow() override { throw PastTheEnd{}; }

 private:
  std::string bytes_;
};

TopoDS_Shape read_brep(const fs::path& path, CadModel::Impl& m) {
  TopoDS_Shape shape;
  std::string why;
  {
    std::ifstream file(path, std::ios::binary);
    BrepBytes bytes(
        std::string((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>()));
    std::istream in(&bytes);
    // A record that does not parse (a number where a letter belongs) sets failbit, and OCCT's
    // reader can then loop for ever re-reading it (a fuzzed Torus_1.brep with two lines gone):
    // it throws instead.
    in.exceptions(std::ios::badbit | std::ios::failbit);
    CoutCapture capture;
    try {
      BRep_Builder builder;
      BRepTools::Read(shape, in, builder);
    } catch (const PastTheEnd&) {
      why = "it ends before its shape does";
      shape.Nullify();
    } catch (const std::ios_base::failure&) {
      why = "a record that does not read as the BREP format says";
      shape.Nullify();
    } catch (const Standard_Failure& e) {
      // A truncated file ends in a lookup of a shape that was never read
      // ("NCollection_IndexedMap::FindKey"): the file is at fault, not OCCT.
      why = e.GetMessageString();
      shape.Nullify();
    }
    const std::string said = capture.text();
    if (!said.empty()) why = why.empty() ? said : said + "; " + why;
  }
  if (shape.IsNull())
    throw Error("'" + path.string() + "' is not a readable OCCT BREP file" +
                (why.empty() ? "" : " (" + why + ")"));
  m.file_unit = "mm (BREP has no unit; assumed)";
  return shape;
}

double signed_volume(const TopoDS_Shape& s) {
  GProp_GProps props;
  BRepGProp::VolumeProperties(s, props);
  return props.Mass();
}

// Builds solids out of the shells and faces of a surface model by sewing; throws when no
// closed shell comes out. The sewing tolerance starts tight (1e-6 of the diagonal) and grows
// tenfold up to 1e-3 while shells stay open: IGES writers leave gaps of their own modelling
// tolerance between trimmed surfaces.
std::vector<TopoDS_Solid> sew_into_solids(const TopoDS_Shape& shape, const BBox3& box,
                                          CadModel::Impl& m) {
  // The plain (tolerance-enlarged) box too: the optimal one of untrimmed IGES surfaces can
  // come out far too small.
  Bnd_Box plain;
  BRepBndLib::Add(shape, plain);
  double diag =
      std::hypot(box.max[0] - box.min[0], box.max[1] - box.min[1], box.max[2] - box.min[2]);
  if (!plain.IsVoid()) diag = std::max(diag, std::sqrt(plain.SquareExtent()));
  int nfaces = 0;
  for (TopExp_Explorer ex(shape, TopAbs_FACE); ex.More(); ex.Next()) ++nfaces;
  if (nfaces == 0) throw Error("the file holds no solid and no surface");
  std::vector<TopoDS_Solid> solids;
  int open_shells = 0, free_edges = 0;
  double tol = 0;
  for (double rel : {1e-6, 1e-5, 1e-4, 1e-3}) {
    tol = std::max(1e-6, rel * diag);
    BRepBuilderAPI_Sewing sewing(tol);
    for (TopExp_Explorer ex(shape, TopAbs_FACE); ex.More(); ex.Next()) sewing.Add(ex.Current());
    sewing.Perform();
    solids.clear();
    open_shells = 0;
    free_edges = sewing.NbFreeEdges();
    const TopoDS_Shape sewn = sewing.SewedShape();
    auto try_shell = [&](const TopoDS_Shell& shell) {
      if (!BRep_Tool::IsClosed(shell)) {
        ++open_shells;
        return;
      }
      ShapeFix_Solid fix;
      solids.push_back(fix.SolidFromShell(shell));
    };
    if (sewn.ShapeType() == TopAbs_FACE) {
      // A single closed face (a sphere as one periodic B-spline surface) sews into no shell.
      TopoDS_Shell shell;
      BRep_Builder b;
      b.MakeShell(shell);
      b.Add(shell, sewn);
      shell.Closed(BRep_Tool::IsClosed(shell));
      try_shell(shell);
    } else {
      for (TopExp_Explorer ex(sewn, TopAbs_SHELL); ex.More(); ex.Next())
        try_shell(TopoDS::Shell(ex.Current()));
    }
    if (!solids.empty() && open_shells == 0) break;
  }
  if (solids.empty()) {
    char msg[200];
    std::snprintf(msg, sizeof msg,
                  "%s surfaces do not close into a solid (%d free edges after sewing with a "
                  "tolerance of %.3g mm)",
                  m.format.c_str(), free_edges, tol);
    throw Error(msg);
  }
  char msg[200];
  std::snprintf(msg, sizeof msg, "sewed %d surfaces into %zu solid(s) (tolerance %.3g mm)", nfaces,
                solids.size(), tol);
  m.warnings.push_back(msg);
  if (open_shells > 0) m.warnings.push_back(std::to_string(open_shells) + " open shell(s) ignored");
  return solids;
}

// Free edges of a solid (edges used by only one face): a solid with any is not closed.
int free_edge_count(const TopoDS_Shape& solid) {
  TopTools_IndexedDataMapOfShapeListOfShape ef;
  TopExp::MapShapesAndAncestors(solid, TopAbs_EDGE, TopAbs_FACE, ef);
  int n = 0;
  for (int i = 1; i <= ef.Extent(); ++i) {
    const TopoDS_Edge& e = TopoDS::Edge(ef.FindKey(i));
    if (BRep_Tool::Degenerated(e)) continue;
    int uses = 0;
    for (const auto& f : ef.FindFromIndex(i)) {
      uses += BRep_Tool::IsClosed(e, TopoDS::Face(f)) ? 2 : 1;
    }
    if (uses < 2) ++n;
  }
  return n;
}

// Solids that touch or overlap, fragmented by OCCT's General Fuse (what Gmsh's BooleanFragments
// runs): where two solids touch they then share one face, where they overlap the common part is
// a solid of its own, so the mesh is one conforming (bonded) assembly. Solids apart are kept.
std::vector<TopoDS_Solid> glue_solids(const std::vector<TopoDS_Solid>& solids, CadModel::Impl& m) {
  BOPAlgo_Builder fuse;
  for (const TopoDS_Solid& s : solids) fuse.AddArgument(s);
  fuse.SetRunParallel(false);  // same input, same output
  fuse.Perform();
  if (fuse.HasErrors())
    throw Error("the solids could not be glued (OpenCASCADE's General Fuse failed)");
  std::vector<TopoDS_Solid> out;
  for (TopExp_Explorer ex(fuse.Shape(), TopAbs_SOLID); ex.More(); ex.Next())
    out.push_back(TopoDS::Solid(ex.Current()));
  if (out.empty()) throw Error("the solids could not be glued (no solid came out)");
  TopTools_IndexedDataMapOfShapeListOfShape face_solids;
  for (const TopoDS_Solid& s : out)
    TopExp::MapShapesAndAncestors(s, TopAbs_FACE, TopAbs_SOLID, face_solids);
  int shared = 0;
  for (int i = 1; i <= face_solids.Extent(); ++i) shared += face_solids(i).Extent() > 1;
  m.warnings.push_back("glued " + std::to_string(solids.size()) + " solids into " +
                       std::to_string(out.size()) + " sharing " + std::to_string(shared) +
                       " face(s) where they touch or overlap");
  return out;
}

SurfaceType surface_type_of(const TopoDS_Face& f) {
  switch (BRepAdaptor_Surface(f, false).GetType()) {
    case GeomAbs_Plane:
      return SurfaceType::Plane;
    case GeomAbs_Cylinder:
      return SurfaceType::Cylinder;
    case GeomAbs_Cone:
      return SurfaceType::Cone;
    case GeomAbs_Sphere:
      return SurfaceType::Sphere;
    case GeomAbs_Torus:
      return SurfaceType::Torus;
    case GeomAbs_BezierSurface:
      return SurfaceType::Bezier;
    case GeomAbs_BSplineSurface:
      return SurfaceType::BSpline;
    case GeomAbs_SurfaceOfRevolution:
      return SurfaceType::Revolution;
    case GeomAbs_SurfaceOfExtrusion:
      return SurfaceType::Extrusion;
    case GeomAbs_OffsetSurface:
      return SurfaceType::Offset;
    default:
      return SurfaceType::Other;
  }
}

bool finite(const gp_Pnt& p) {
  return std::isfinite(p.X()) && std::isfinite(p.Y()) && std::isfinite(p.Z());
}

// A face whose surface gives points that are not numbers somewhere (a damaged file).
Error damaged_surface(std::size_t face_index) {
  return Error("face " + std::to_string(face_index + 1) +
               ": its surface gives points that are not finite numbers (a damaged surface in the "
               "CAD file)");
}

// Whether a, grown by 1e-9 of its size, lies in b: an optimal box can stick out of the cheap one
// by rounding (1.8e-15 mm on a 5 mm part, a plane's corner against its edges' points).
bool inside(const Bnd_Box& a, const Bnd_Box& b) {
  if (a.IsVoid() || b.IsVoid()) return false;  // no cheap box: the optimal one is made
  double a0[3], a1[3], b0[3], b1[3];
  a.Get(a0[0], a0[1], a0[2], a1[0], a1[1], a1[2]);
  b.Get(b0[0], b0[1], b0[2], b1[0], b1[1], b1[2]);
  const double margin = 1e-9 * std::sqrt(a.SquareExtent()) + 1e-12;
  for (int k = 0; k < 3; ++k)
    if (a0[k] - margin < b0[k] || a1[k] + margin > b1[k]) return false;
  return true;
}

}  // namespace

// BRepBndLib::AddOptimal's box, the union of the faces' optimal boxes (for a shape whose edges
// all bound faces). An optimal box is a particle-swarm search per coordinate on a curved face
// (5 s for the 663 faces of 0082_MVE), so it is made only for the faces whose cheap box (poles or
// exact patch, enlarged by the face's tolerance; it holds the optimal one) reaches outside the
// union so far, the faces holding the cheap boxes' extremes first.
BBox3 shape_bbox(const TopoDS_Shape& shape) {
  Bnd_Box box;
  if (TopExp_Explorer(shape, TopAbs_EDGE, TopAbs_FACE).More() ||
      TopExp_Explorer(shape, TopAbs_VERTEX, TopAbs_EDGE).More()) {
    BRepBndLib::AddOptimal(shape, box, false, false);
  } else {
    std::vector<TopoDS_Face> faces;
    std::vector<Bnd_Box> cheap;
    for (TopExp_Explorer ex(shape, TopAbs_FACE); ex.More(); ex.Next()) {
      faces.push_back(TopoDS::Face(ex.Current()));
      cheap.emplace_back();
      BRepBndLib::Add(faces.back(), cheap.back(), false);
    }
    // The first face reaching furthest along -x, -y, -z, +x, +y, +z by its cheap box.
    const std::size_t none = faces.size();
    std::array<std::size_t, 6> best;
    best.fill(none);
    std::array<double, 6> extreme{};
    for (std::size_t f = 0; f < faces.size(); ++f) {
      if (cheap[f].IsVoid()) continue;
      double lo[3], hi[3];
      cheap[f].Get(lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]);
      for (int k = 0; k < 6; ++k) {
        const double x = k < 3 ? -lo[k] : hi[k - 3];
        if (best[k] == none || x > extreme[k]) {
          best[k] = f;
          extreme[k] = x;
        }
      }
    }
    std::vector<std::size_t> order;
    for (const std::size_t f : best)
      if (f != none) order.push_back(f);
    for (std::size_t f = 0; f < faces.size(); ++f) order.push_back(f);
    std::vector<char> done(faces.size(), 0);
    for (const std::size_t f : order) {
      if (done[f] || inside(cheap[f], box)) continue;
      done[f] = 1;
      Bnd_Box b;
      BRepBndLib::AddOptimal(faces[f], b, false, false);
      box.Add(b);
    }
  }
  BBox3 b;
  if (box.IsVoid()) return b;
  box.Get(b.min[0], b.min[1], b.min[2], b.max[0], b.max[1], b.max[2]);
  return b;
}

void CadModel::Impl::build_tables() {
  TopExp::MapShapes(part, TopAbs_VERTEX, vertex_map);
  TopExp::MapShapes(part, TopAbs_EDGE, edge_map);
  TopExp::MapShapes(part, TopAbs_FACE, face_map);
  TopExp::MapShapes(part, TopAbs_SOLID, solid_map);

  for (int i = 1; i <= vertex_map.Extent(); ++i) {
    const TopoDS_Vertex& v = TopoDS::Vertex(vertex_map(i));
    vertices.push_back(BRep_Tool::Pnt(v));
    vertex_tol.push_back(BRep_Tool::Tolerance(v));
  }

  edges.resize(edge_map.Extent());
  for (int i = 1; i <= edge_map.Extent(); ++i) {
    EdgeData& e = edges[i - 1];
    e.edge = TopoDS::Edge(edge_map(i).Oriented(TopAbs_FORWARD));
    e.degenerate = BRep_Tool::Degenerated(e.edge);
    BRep_Tool::Range(e.edge, e.first, e.last);
    if (!e.degenerate) {
      e.curve = BRep_Tool::Curve(e.edge, e.first, e.last);
      if (e.curve.IsNull()) e.degenerate = true;
    }
    TopoDS_Vertex v1, v2;
    TopExp::Vertices(e.edge, v1, v2);
    e.vertices = {v1.IsNull() ? 0 : vertex_map.FindIndex(v1),
                  v2.IsNull() ? 0 : vertex_map.FindIndex(v2)};
    if (!e.degenerate) {
      e.length = GCPnts_AbscissaPoint::Length(BRepAdaptor_Curve(e.edge));
      // A curve whose numbers are damaged (a circle's centre at NaN in a fuzzed BREP, seed 89)
      // gives points that are not numbers: every later stage would compute with them.
      if (!finite(e.curve->Value(0.5 * (e.first + e.last))) || !std::isfinite(e.length))
        throw Error("edge " + std::to_string(i) +
                    ": its curve gives points that are not finite numbers (a damaged curve in "
                    "the CAD file)");
    }
  }

  faces.resize(face_map.Extent());
  solids.resize(solid_map.Extent());
  std::vector<bool> seen(faces.size(), false);
  for (int s = 1; s <= solid_map.Extent(); ++s) {
    SolidData& sd = solids[s - 1];
    sd.solid = TopoDS::Solid(solid_map(s));
    for (TopExp_Explorer ex(sd.solid, TopAbs_FACE); ex.More(); ex.Next()) {
      const int f = face_map.FindIndex(ex.Current());
      if (std::find(sd.faces.begin(), sd.faces.end(), f) == sd.faces.end()) sd.faces.push_back(f);
      faces[f - 1].solids.push_back(s);
      if (!seen[f - 1]) {
        seen[f - 1] = true;
        faces[f - 1].face = TopoDS::Face(ex.Current());
      }
    }
    sd.volume = signed_volume(sd.solid);
    volume += sd.volume;
  }

  for (std::size_t i = 0; i < faces.size(); ++i) {
    FaceData& fd = faces[i];
    if (!seen[i]) fd.face = TopoDS::Face(face_map(static_cast<int>(i) + 1));
    fd.reversed = fd.face.Orientation() == TopAbs_REVERSED;
    fd.surface = BRep_Tool::Surface(fd.face);
    // A surface the reader could not build (a cone's half-angle of 1e308 in a damaged BREP; the
    // fuzz, seed 71) is null here.
    if (fd.surface.IsNull())
      throw Error("face " + std::to_string(i + 1) +
                  " has no surface (a damaged surface in the CAD file)");
    fd.type = surface_type_of(fd.face);
    BRepTools::UVBounds(fd.face, fd.bounds[0], fd.bounds[1], fd.bounds[2], fd.bounds[3]);
    // The same for a surface (a plane's origin at NaN).
    if (!finite(fd.surface->Value(0.5 * (fd.bounds[0] + fd.bounds[1]),
                                  0.5 * (fd.bounds[2] + fd.bounds[3]))))
      throw damaged_surface(i);
    if (fd.surface->IsUPeriodic()) fd.periods[0] = fd.surface->UPeriod();
    if (fd.surface->IsVPeriodic()) fd.periods[1] = fd.surface->VPeriod();
    // Coedges in wire order; the face is taken FORWARD so the wire orientation is the one
    // of the parameter plane (outer wire counter-clockwise).
    const TopoDS_Face fwd = TopoDS::Face(fd.face.Oriented(TopAbs_FORWARD));
    const TopoDS_Wire outer = BRepTools::OuterWire(fwd);
    std::vector<TopoDS_Wire> wires;
    if (!outer.IsNull()) wires.push_back(outer);
    for (TopExp_Explorer w(fwd, TopAbs_WIRE); w.More(); w.Next())
      if (!w.Current().IsSame(outer)) wires.push_back(TopoDS::Wire(w.Current()));
    for (std::size_t w = 0; w < wires.size(); ++w) {
      // Connection order (BRepTools_WireExplorer); a defective wire it cannot walk whole is
      // taken in storage order and its gaps are bridged by the mesher.
      std::vector<TopoDS_Edge> ordered, stored;
      for (BRepTools_WireExplorer wx(wires[w], fwd); wx.More(); wx.Next())
        ordered.push_back(wx.Current());
      for (TopExp_Explorer ex(wires[w], TopAbs_EDGE); ex.More(); ex.Next())
        stored.push_back(TopoDS::Edge(ex.Current()));
      if (ordered.size() != stored.size()) {
        ordered = stored;
        warnings.push_back("face " + std::to_string(i + 1) + ": a wire is not connected in order");
      }
      for (const TopoDS_Edge& ed : ordered) {
        CoEdge ce;
        ce.edge = edge_map.FindIndex(ed);
        ce.reversed = ed.Orientation() == TopAbs_REVERSED;
        ce.wire = static_cast<int>(w);
        ce.seam = BRep_Tool::IsClosed(ed, fwd);
        double a = 0, b = 0;
        CoEdgeData cd{ed, BRep_Tool::CurveOnSurface(ed, fwd, a, b)};
        if (cd.pcurve.IsNull())
          throw Error("face " + std::to_string(i + 1) + ": edge " + std::to_string(ce.edge) +
                      " has no curve in the face's parameter plane");
        fd.coedges.push_back(ce);
        fd.coedge_data.push_back(cd);
        auto& ef = edges[ce.edge - 1].faces;
        if (std::find(ef.begin(), ef.end(), static_cast<int>(i) + 1) == ef.end())
          ef.push_back(static_cast<int>(i) + 1);
      }
    }
    GProp_GProps props;
    BRepGProp::SurfaceProperties(fd.face, props);
    fd.area = props.Mass();
    fd.centroid = to_vec(props.CentreOfMass());
    // NaN inside a face whose middle is finite (a B-spline's damaged weights, the fuzz, seed 97)
    // shows in its integrals.
    if (!std::isfinite(fd.area) || !std::isfinite(fd.centroid[0]) ||
        !std::isfinite(fd.centroid[1]) || !std::isfinite(fd.centroid[2]))
      throw damaged_surface(i);
    if (!fd.solids.empty()) area += fd.area;
  }
  face_bbox.resize(faces.size());
  solid_bbox.resize(solids.size());
}

CadModel CadModel::read(const std::filesystem::path& path, const CadReadOptions& options) {
  silence_occt();
  std::error_code ec;
  if (!fs::exists(path, ec)) throw Error("cannot open '" + path.string() + "': no such file");
  if (fs::is_directory(path, ec))
    throw Error("'" + path.string() + "' is a directory, not a CAD file");
  if (fs::file_size(path, ec) == 0) throw Error("'" + path.string() + "' is empty");
  if (!std::ifstream(path).good()) throw Error("cannot open '" + path.string() + "' for reading");

  auto impl = std::make_unique<Impl>();
  Impl& m = *impl;
  const std::string ext = lower_case(path.extension().string());
  try {
    TopoDS_Shape shape;
    if (ext == ".step" || ext == ".stp") {
      m.format = "STEP";
      shape = read_step(path, m);
    } else if (ext == ".iges" || ext == ".igs") {
      m.format = "IGES";
      shape = read_iges(path, m);
    } else if (ext == ".brep" || ext == ".rle" || ext == ".brp") {
      m.format = "BREP";
      shape = read_brep(path, m);
    } else {
      throw Error("'" + path.string() + "': unknown CAD format '" + ext +
                  "' (expected .step/.stp, .iges/.igs, .brep/.rle)");
    }
    if (shape.IsNull()) throw Error("'" + path.string() + "' holds no shape");

    std::vector<TopoDS_Solid> solids;
    for (TopExp_Explorer ex(shape, TopAbs_SOLID); ex.More(); ex.Next())
      solids.push_back(TopoDS::Solid(ex.Current()));
    if (solids.empty()) {
      solids = sew_into_solids(shape, shape_bbox(shape), m);
    } else {
      int loose = 0;
      for (TopExp_Explorer ex(shape, TopAbs_FACE, TopAbs_SOLID); ex.More(); ex.Next()) ++loose;
      if (loose > 0)
        m.warnings.push_back(std::to_string(loose) + " face(s) outside any solid ignored");
    }
    BRep_Builder builder;
    TopoDS_Compound part;
    builder.MakeCompound(part);
    for (std::size_t i = 0; i < solids.size(); ++i) {
      TopoDS_Solid& s = solids[i];
      const int free = free_edge_count(s);
      if (free > 0)
        throw Error("solid " + std::to_string(i + 1) + " is not closed (" + std::to_string(free) +
                    " free edges)");
      // An inside-out solid (negative volume) is turned around so its faces point outward.
      if (signed_volume(s) < 0) {
        s.Reverse();
        m.warnings.push_back("solid " + std::to_string(i + 1) + " was inside out; reversed");
      }
    }
    if (options.glue && solids.size() > 1) solids = glue_solids(solids, m);
    for (const TopoDS_Solid& s : solids) builder.Add(part, s);
    m.part = part;
    m.build_tables();
  } catch (const Standard_Failure& e) {
    throw Error("OpenCASCADE failed on '" + path.string() + "': " + e.GetMessageString());
  }
  return CadModel(std::move(impl));
}

CadModel::CadModel(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
CadModel::CadModel(CadModel&&) noexcept = default;
CadModel& CadModel::operator=(CadModel&&) noexcept = default;
CadModel::~CadModel() = default;

const std::string& CadModel::format() const {
  return impl_->format;
}
const std::string& CadModel::file_unit() const {
  return impl_->file_unit;
}
double CadModel::unit_scale() const {
  return impl_->unit_scale;
}
const std::vector<std::string>& CadModel::warnings() const {
  return impl_->warnings;
}
int CadModel::num_vertices() const {
  return static_cast<int>(impl_->vertices.size());
}
int CadModel::num_edges() const {
  return static_cast<int>(impl_->edges.size());
}
int CadModel::num_faces() const {
  return static_cast<int>(impl_->faces.size());
}
int CadModel::num_solids() const {
  return static_cast<int>(impl_->solids.size());
}
const std::vector<int>& CadModel::faces_of_solid(int s) const {
  return impl_->solids.at(s - 1).faces;
}
double CadModel::solid_volume(int s) const {
  return impl_->solids.at(s - 1).volume;
}
BBox3 CadModel::solid_bbox(int s) const {
  const auto& d = impl_->solids.at(static_cast<std::size_t>(s - 1));
  if (impl_->solids.size() == 1) return bbox();  // the same faces: the same box
  std::lock_guard lock(impl_->bbox_mutex);
  auto& b = impl_->solid_bbox[static_cast<std::size_t>(s - 1)];
  if (!b) b = shape_bbox(d.solid);
  return *b;
}
double CadModel::volume() const {
  return impl_->volume;
}
BBox3 CadModel::bbox() const {
  std::lock_guard lock(impl_->bbox_mutex);
  if (!impl_->part_bbox) impl_->part_bbox = shape_bbox(impl_->part);
  return *impl_->part_bbox;
}
double CadModel::area() const {
  return impl_->area;
}

}  // namespace hexfem
