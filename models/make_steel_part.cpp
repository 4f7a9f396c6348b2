// Builds the bundled steel part (models/steel_part.step, see models/README.md): a stepped bar
// with two through holes and a fillet at the step, in the spirit of Fig. 32 of Baudouin et al.
// 2014. Lengths in mm. The program reads its own STEP back and prints the face ids the way
// hexfem numbers them (TopExp::MapShapes(shape, TopAbs_FACE), 1-based), so the README can name
// the clamped end face reliably.
//
// Usage: make_steel_part <out.step>
#include <APIHeaderSection_MakeHeader.hxx>
#include <BRepAdaptor_Surface.hxx>
#include <BRepAlgoAPI_Cut.hxx>
#include <BRepBndLib.hxx>
#include <BRepFilletAPI_MakeFillet.hxx>
#include <BRepGProp.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <BRep_Tool.hxx>
#include <Bnd_Box.hxx>
#include <GProp_GProps.hxx>
#include <IFSelect_ReturnStatus.hxx>
#include <Interface_Static.hxx>
#include <STEPControl_Reader.hxx>
#include <STEPControl_Writer.hxx>
#include <StepData_StepModel.hxx>
#include <TCollection_HAsciiString.hxx>
#include <TopExp.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Shape.hxx>
#include <TopoDS_Vertex.hxx>
#include <cmath>
#include <cstdio>
#include <gp_Ax2.hxx>
#include <gp_Pnt.hxx>
#include <stdexcept>
#include <string>

namespace {

// Dimensions (mm). Clamped end: the face x = 0 of the thick part.
constexpr double kLength = 80.0;  // along x
constexpr double kWidth = 20.0;   // along y
constexpr double kThick = 10.0;   // along z, thick half x in [0, kStepX]
constexpr double kThin = 5.0;     // along z, thin half x in [kStepX, kLength]
constexpr double kStepX = 40.0;   // position of the step
constexpr double kFilletR = 3.0;  // fillet of the concave step edge (x = kStepX, z = kThin)
constexpr double kHole1X = 20.0;  // through hole in the thick half, along z
constexpr double kHole1D = 8.0;
constexpr double kHole2X = 62.0;  // through hole in the thin half, along z
constexpr double kHole2D = 6.0;

bool near(double a, double b) {
  return std::abs(a - b) < 1e-6;
}

TopoDS_Shape make_part() {
  TopoDS_Shape bar = BRepPrimAPI_MakeBox(gp_Pnt(0, 0, 0), gp_Pnt(kLength, kWidth, kThick)).Shape();
  TopoDS_Shape cut =
      BRepPrimAPI_MakeBox(gp_Pnt(kStepX, 0, kThin), gp_Pnt(kLength, kWidth, kThick)).Shape();
  BRepAlgoAPI_Cut step(bar, cut);
  if (!step.IsDone()) throw std::runtime_error("step cut failed");
  TopoDS_Shape stepped = step.Shape();

  // The concave edge of the step: a line along y at x = kStepX, z = kThin.
  BRepFilletAPI_MakeFillet fillet(stepped);
  TopTools_IndexedMapOfShape edges;  // unique edges (an explorer visits each once per face)
  TopExp::MapShapes(stepped, TopAbs_EDGE, edges);
  int n_edges = 0;
  for (int i = 1; i <= edges.Extent(); ++i) {
    const TopoDS_Edge& e = TopoDS::Edge(edges(i));
    gp_Pnt a = BRep_Tool::Pnt(TopExp::FirstVertex(e));
    gp_Pnt b = BRep_Tool::Pnt(TopExp::LastVertex(e));
    if (near(a.X(), kStepX) && near(b.X(), kStepX) && near(a.Z(), kThin) && near(b.Z(), kThin)) {
      fillet.Add(kFilletR, e);
      ++n_edges;
    }
  }
  if (n_edges != 1)
    throw std::runtime_error("expected one step edge, found " + std::to_string(n_edges));
  fillet.Build();
  if (!fillet.IsDone()) throw std::runtime_error("fillet failed");
  TopoDS_Shape part = fillet.Shape();

  const double y = kWidth / 2;
  const double holes[2][2] = {{kHole1X, kHole1D}, {kHole2X, kHole2D}};
  for (const auto& h : holes) {
    gp_Ax2 axis(gp_Pnt(h[0], y, -1.0), gp::DZ());
    TopoDS_Shape cyl = BRepPrimAPI_MakeCylinder(axis, h[1] / 2, kThick + 2.0).Shape();
    BRepAlgoAPI_Cut drill(part, cyl);
    if (!drill.IsDone()) throw std::runtime_error("hole cut failed");
    part = drill.Shape();
  }
  return part;
}

void write_step(const TopoDS_Shape& shape, const std::string& path) {
  Interface_Static::SetCVal("write.step.unit", "MM");
  Interface_Static::SetCVal("write.step.schema", "AP214IS");
  STEPControl_Writer writer;
  if (writer.Transfer(shape, STEPControl_AsIs) != IFSelect_RetDone)
    throw std::runtime_error("STEP transfer failed");
  // Fixed header fields so that rerunning the program gives a byte-identical file.
  APIHeaderSection_MakeHeader header(writer.Model());
  header.SetName(new TCollection_HAsciiString("steel_part"));
  header.SetTimeStamp(new TCollection_HAsciiString("2024-01-01T00:00:00"));
  header.SetAuthorValue(1, new TCollection_HAsciiString("hexfem models/make_steel_part"));
  header.SetOrganizationValue(1, new TCollection_HAsciiString("hexfem"));
  header.SetOriginatingSystem(new TCollection_HAsciiString("hexfem make_steel_part"));
  if (writer.Write(path.c_str()) != IFSelect_RetDone)
    throw std::runtime_error("cannot write " + path);
}

const char* surface_name(GeomAbs_SurfaceType t) {
  switch (t) {
    case GeomAbs_Plane:
      return "plane";
    case GeomAbs_Cylinder:
      return "cylinder";
    default:
      return "other";
  }
}

// Reads the STEP back as hexfem does and prints each face with its id, type and bounding box.
void report_faces(const std::string& path) {
  STEPControl_Reader reader;
  if (reader.ReadFile(path.c_str()) != IFSelect_RetDone)
    throw std::runtime_error("cannot read back " + path);
  reader.TransferRoots();
  TopoDS_Shape shape = reader.OneShape();

  GProp_GProps props;
  BRepGProp::VolumeProperties(shape, props);
  Bnd_Box all;
  BRepBndLib::AddOptimal(shape, all, false, false);
  double x0, y0, z0, x1, y1, z1;
  all.Get(x0, y0, z0, x1, y1, z1);
  std::printf("read back: volume %.4f mm^3, bbox [%.3f %.3f] x [%.3f %.3f] x [%.3f %.3f] mm\n",
              props.Mass(), x0, x1, y0, y1, z0, z1);

  TopTools_IndexedMapOfShape faces;
  TopExp::MapShapes(shape, TopAbs_FACE, faces);
  std::printf("%d faces (id = 1-based index in TopExp::MapShapes(shape, TopAbs_FACE)):\n",
              faces.Extent());
  int clamped = 0;
  for (int i = 1; i <= faces.Extent(); ++i) {
    const TopoDS_Face& f = TopoDS::Face(faces(i));
    BRepAdaptor_Surface s(f);
    Bnd_Box b;
    BRepBndLib::AddOptimal(f, b, false, false);
    double a0, b0, c0, a1, b1, c1;
    b.Get(a0, b0, c0, a1, b1, c1);
    GProp_GProps fp;
    BRepGProp::SurfaceProperties(f, fp);
    std::printf("  face %2d  %-8s area %8.3f  x [%7.3f %7.3f] y [%7.3f %7.3f] z [%7.3f %7.3f]\n", i,
                surface_name(s.GetType()), fp.Mass(), a0, a1, b0, b1, c0, c1);
    if (s.GetType() == GeomAbs_Plane && std::abs(a0) < 1e-6 && std::abs(a1) < 1e-6) {
      if (clamped != 0) throw std::runtime_error("two faces at x = 0");
      clamped = i;
    }
  }
  if (clamped == 0) throw std::runtime_error("no planar face at x = 0");
  std::printf("clamped end face (planar, x = 0): id %d\n", clamped);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s <out.step>\n", argv[0]);
    return 2;
  }
  try {
    TopoDS_Shape part = make_part();
    GProp_GProps props;
    BRepGProp::VolumeProperties(part, props);
    std::printf("built: volume %.4f mm^3\n", props.Mass());
    write_step(part, argv[1]);
    std::printf("wrote %s\n", argv[1]);
    report_faces(argv[1]);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "make_steel_part: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
