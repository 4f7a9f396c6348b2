// Speed of the recombination stages alone, on the tet mesh of a CAD part: the part is meshed up
// to TetGen once, then the hex enumeration, the hex placement and the prism stage are timed
// `repeat` times each (best and median wall time, CPU time of the best), so that a change in
// one stage is measured without the noise of the rest of the pipeline.
//   bench_recombine <part.step|.iges|.brep> <h> [--repeat N] [--bands 0.8,0.6]
// The hex timing is place_hexes_greedily (enumeration and placement, band by band: --bands, the
// default HexOptions' otherwise; --bands none: one band).
// Threads: OMP_NUM_THREADS.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <string>
#include <vector>

#include "mesher/cad/cad_model.hpp"
#include "mesher/frame_field_3d.hpp"
#include "mesher/mesh/error.hpp"
#include "mesher/recombine_hex.hpp"
#include "mesher/recombine_prism_pyramid.hpp"
#include "mesher/solid_locator.hpp"
#include "mesher/surface_pipeline.hpp"
#include "mesher/tetrahedralize.hpp"
#include "mesher/volume_pipeline.hpp"
#include "mesher/volume_points.hpp"
#include "mesher/volume_slivers.hpp"

using namespace hexfem;

namespace {

double cpu_now() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

struct Timing {
  std::vector<double> wall, cpu;
  void add(double w, double c) {
    wall.push_back(w);
    cpu.push_back(c);
  }
  void print(const char* name) const {
    std::vector<double> w = wall;
    std::sort(w.begin(), w.end());
    const auto best = std::min_element(wall.begin(), wall.end()) - wall.begin();
    std::printf("%-22s best %7.3f s wall (%7.3f s cpu), median %7.3f s wall, %zu runs\n", name,
                w.front(), cpu[best], w[w.size() / 2], w.size());
  }
};

template <class F>
void timed(Timing& t, F f) {
  const auto w0 = std::chrono::steady_clock::now();
  const double c0 = cpu_now();
  f();
  t.add(std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count(),
        cpu_now() - c0);
}

}  // namespace

int main(int argc, char** argv) {
  try {
    if (argc < 3) {
      std::fprintf(stderr, "usage: %s <part> <h> [--repeat N]\n", argv[0]);
      return 2;
    }
    const double h = std::stod(argv[2]);
    int repeat = 5;
    std::vector<float> bands = HexOptions{}.quality_bands;
    for (int i = 3; i < argc; ++i) {
      const std::string a = argv[i];
      if (a == "--repeat" && i + 1 < argc) {
        repeat = std::max(1, std::stoi(argv[++i]));
      } else if (a == "--bands" && i + 1 < argc) {
        bands.clear();
        const std::string list = argv[++i];
        for (std::size_t at = 0; list != "none" && at < list.size();) {
          const std::size_t comma = std::min(list.find(',', at), list.size());
          bands.push_back(std::stof(list.substr(at, comma - at)));
          at = comma + 1;
        }
      } else
        throw Error("unknown option " + a);
    }
    const CadModel cad = CadModel::read(argv[1]);
    SurfaceOptions so;
    so.h = h;
    SurfaceMesh surface = mesh_surface(cad, so, nullptr);
    const FrameField3D field(surface);
    const SolidLocator locator(surface);
    const VolumeOptions defaults;  // as `hexfem mesh` without options
    VolumePointsOptions po;
    po.k = defaults.k;
    po.inherit_frame = defaults.inherit_frame;
    const VolumePoints points = insert_volume_points(surface, field, locator, po);
    TetMesh tets = tetrahedralize(surface, points.points, locator);
    drop_flat_boundary_tets(tets, surface, defaults.flat_tet_quality);
    std::printf("%s h=%g: %zu vertices, %zu tets\n", argv[1], h, tets.nodes.size(),
                tets.tets.size());

    Timing t_topo, t_hex, t_prism;
    std::size_t ncand = 0, nhex = 0, nprism = 0;
    for (int r = 0; r < repeat; ++r) {
      const TetTopology* topo = nullptr;
      timed(t_topo, [&] { topo = new TetTopology(tets, surface); });
      RecombineLimits limits;
      limits.min_quality = defaults.min_quality;
      limits.fill.max_volume_gap = defaults.max_volume_gap;
      limits.fill.max_face_twist = defaults.max_face_twist;
      HexOptions ho;
      ho.min_quality = limits.min_quality;
      ho.fill = limits.fill;
      ho.quality_bands = bands;
      RecombineState state(*topo, limits);
      ConformityIndex index;
      ncand = 0;
      timed(t_hex, [&] { nhex = place_hexes_greedily(state, ho, index, &ncand); });
      timed(t_prism, [&] {
        std::vector<Candidate> pc = enumerate_prisms(state);
        nprism = place_greedily(state, pc, index);
      });
      delete topo;
    }
    std::printf("hex candidates %zu, hexes %zu, prisms %zu\n", ncand, nhex, nprism);
    t_topo.print("tet topology");
    t_hex.print("hexes");
    t_prism.print("prisms");
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_recombine: error: %s\n", e.what());
    return 1;
  }
}
