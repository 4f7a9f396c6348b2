// The whole mesher in the paper's order: CAD -> surface mesh (size field, cross field, packing of
// parallelograms, triangulation) -> volume (3D frontal points, TetGen, hexes, prisms, pyramids).
//
// Takes: a CAD model (or file) and MeshOptions.
// Gives: a valid MixedMesh and a MeshReport.
// Keeps: no inverted or flat cell and a watertight boundary, or a one-line Error and no mesh.
#pragma once

#include <string>
#include <vector>

#include "mesher/cad/cad_model.hpp"
#include "mesher/mesh/mesh_stats.hpp"
#include "mesher/surface_pipeline.hpp"
#include "mesher/volume_pipeline.hpp"

namespace hexfem {

struct MeshOptions {
  CadReadOptions read;     // read.glue: solids that touch fragmented into a bonded assembly
  SurfaceOptions surface;  // surface.h is the target size (mm), surface.force lifts the limits
  VolumeOptions volume;
  double max_volume_points = 20e6;  // estimated interior points (V / h^3) allowed without force
  // Memory the run may use (bytes) before an h is refused without force; 0: what the machine
  // has available now (MemAvailable).
  double memory_limit_bytes = 0;
};

// One CAD solid's mesh volume against its CAD volume (mm^3).
struct SolidVolumeError {
  int solid = 0;
  double cad_volume = 0;
  double mesh_volume = 0;
  double error = 0;  // (mesh - CAD) / CAD
};

struct MeshReport {
  std::string file_unit;
  MeshStats stats;          // of the emitted mesh (checked: no inverted/flat cell, watertight)
  double cad_volume = 0;    // mm^3
  double mesh_volume = 0;   // sum of the cell volumes, mm^3
  double volume_error = 0;  // (mesh - CAD) / CAD
  // Per solid when the part has more than one: the whole can be right while a small solid (an
  // assembly's bolt, with its own material) is off.
  std::vector<SolidVolumeError> solids;
  // What the curvature retries drive down: volume_error for one solid; for several, the error of
  // the solid farthest off (at a coarse h a glued bolt loses to its chords what the plate around
  // it gains, and the whole part's volume hides it).
  double retry_error = 0;
  std::vector<double> solid_cad_volumes;  // by solid id (0 unused), for retry_error
  double cad_seconds = 0;                 // reading the CAD file (when mesh_file is used)
  SurfaceReport surface;
  VolumeReport volume;
  double total_seconds = 0;
  // Things the user should know about a mesh that is valid (e.g. a volume far off the CAD's).
  std::vector<std::string> warnings;
  // CAD faces meshed again at a finer size because the mesh at h had flat or inverted cells on
  // them or a surface that crossed itself there (empty when the first mesh was valid).
  std::vector<int> refined_faces;
};

// The warning a mesh `volume_error` ((mesh - CAD) / CAD) off the CAD's volume at size h gets
// (mesh_part adds it to MeshReport::warnings); empty within 2 %.
std::string volume_warning(double volume_error, double h);

// The solids' errors from the mesh's volume per solid (empty for a part of one solid), and the
// warning for those off by more than 2 % (empty if none).
std::vector<SolidVolumeError> solid_volume_errors(const CadModel& cad,
                                                  const std::vector<SolidVolume>& mesh_volumes);
std::string solid_volume_warning(const std::vector<SolidVolumeError>& solids, double h);

// The surface mesh of every solid (`hexfem mesh --dim 2`), meshed again with a curvature bound
// (16 elements per turn or twice the user's, doubled while it gets closer, as mesh_part does)
// where its chords cut more than 5 % off the part or off one of its solids; the closest is kept
// and `warnings` says so.
SurfaceMesh mesh_surface_closest(const CadModel& cad, const SurfaceOptions& options,
                                 SurfaceReport& report, std::vector<std::string>& warnings);

// Hex-dominant mesh of every solid of the part. Throws hexfem::Error (one line) on bad options,
// an h that would give more than max_volume_points without surface.force, or a failing stage.
MixedMesh mesh_part(const CadModel& cad, const MeshOptions& options, MeshReport* report = nullptr);

// Reads the CAD file as mesh_file does (its time in report.cad_seconds), for a caller that
// needs the model again after mesh_part (the order-2 nodes on its geometry).
CadModel read_cad_to_mesh(const std::filesystem::path& path, const MeshOptions& options,
                          MeshReport& report);

// Reads the CAD file and meshes it.
MixedMesh mesh_file(const std::filesystem::path& path, const MeshOptions& options,
                    MeshReport* report = nullptr);

}  // namespace hexfem
