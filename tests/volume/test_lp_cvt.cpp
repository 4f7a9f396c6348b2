// The Lp-CVT optimisation of the interior points (volume_points_lpcvt.hpp, --lp-cvt): the
// energy of one cube cell against its closed form, the gradient against central differences,
// a jittered lattice back on the lattice (a cube of cubes is the minimiser), and a part meshed
// with it: valid, its volume kept, the same bytes for 1 and 2 threads.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "mesher/splitmix.hpp"
#include "mesher/volume_points_lpcvt.hpp"
#include "tests/cad/cad_test_util.hpp"

namespace hexfem {
namespace {

const Frame kAxes{Vec3{1, 0, 0}, Vec3{0, 1, 0}, Vec3{0, 0, 1}};

// Jitter in [-0.5, 0.5) that is the same everywhere.
double jitter(std::uint64_t i) {
  return splitmix_at(i) - 0.5;
}

// A lattice of spacing a, n + 1 points a side: the boundary points first (fixed), then the
// interior ones jittered by up to `amount` a, then one layer of ghosts outside (closing the
// boundary points' cells).
struct Lattice {
  std::vector<Vec3> points;
  std::size_t ns = 0, ni = 0;
};

Lattice lattice(int n, double a, double amount) {
  Lattice l;
  std::vector<Vec3> interior, ghosts;
  for (int i = -1; i <= n + 1; ++i)
    for (int j = -1; j <= n + 1; ++j)
      for (int k = -1; k <= n + 1; ++k) {
        const Vec3 x{a * i, a * j, a * k};
        const bool outside = i < 0 || j < 0 || k < 0 || i > n || j > n || k > n;
        const bool boundary = i == 0 || j == 0 || k == 0 || i == n || j == n || k == n;
        if (outside)
          ghosts.push_back(x);
        else if (boundary)
          l.points.push_back(x);
        else
          interior.push_back(x);
      }
  l.ns = l.points.size();
  l.ni = interior.size();
  for (std::size_t p = 0; p < interior.size(); ++p)
    for (int d = 0; d < 3; ++d) interior[p][d] += amount * a * jitter(3 * p + d);
  l.points.insert(l.points.end(), interior.begin(), interior.end());
  l.points.insert(l.points.end(), ghosts.begin(), ghosts.end());
  return l;
}

// One interior point in a 3x3x3 lattice: its Voronoi cell is the cube of side a around it, and
// the boundary points' cells are open (on the convex hull) so they do not count. The integral
// of sum_k (u_k / h)^p over a cube of side a: 3 a^(p+3) / (2^p (p+1) h^p).
TEST(LpCvt, TheEnergyOfACubeCellIsItsClosedForm) {
  for (int p : {2, 8}) {
    const double a = 0.7, h = 0.5;
    std::vector<Vec3> pts;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        for (int k = 0; k < 3; ++k)
          if (!(i == 1 && j == 1 && k == 1)) pts.push_back({a * i, a * j, a * k});
    pts.push_back({a, a, a});
    const std::vector<Frame> frame(pts.size(), kAxes);
    const std::vector<double> size(pts.size(), h);
    const double exact = 3 * std::pow(a, p + 3) / (std::pow(2.0, p) * (p + 1) * std::pow(h, p));
    EXPECT_NEAR(lp_cvt_energy(pts, pts.size() - 1, 1, frame, size, p, nullptr), exact,
                1e-12 * exact)
        << "p = " << p;
  }
}

TEST(LpCvt, TheGradientIsTheEnergysDerivative) {
  const Lattice l = lattice(4, 1.0, 0.4);
  const std::size_t n = l.ns + l.ni;
  std::vector<Frame> frame(n, kAxes);
  // A turned frame on some points, and sizes that vary, so every term of the gradient counts.
  const double c = std::cos(0.3), s = std::sin(0.3);
  for (std::size_t i = 0; i < n; i += 3) frame[i] = {Vec3{c, s, 0}, Vec3{-s, c, 0}, Vec3{0, 0, 1}};
  std::vector<double> size(n);
  for (std::size_t i = 0; i < n; ++i) size[i] = 0.9 + 0.2 * (jitter(1000 + i) + 0.5);
  std::vector<Vec3> grad;
  lp_cvt_energy(l.points, l.ns, l.ni, frame, size, 8, &grad);
  ASSERT_EQ(grad.size(), l.ni);
  double worst = 0, largest = 0;
  for (std::size_t i = 0; i < l.ni; ++i)
    for (int d = 0; d < 3; ++d) {
      const double eps = 1e-6;
      std::vector<Vec3> up = l.points, down = l.points;
      up[l.ns + i][d] += eps;
      down[l.ns + i][d] -= eps;
      const double fd = (lp_cvt_energy(up, l.ns, l.ni, frame, size, 8, nullptr) -
                         lp_cvt_energy(down, l.ns, l.ni, frame, size, 8, nullptr)) /
                        (2 * eps);
      worst = std::max(worst, std::abs(fd - grad[i][d]));
      largest = std::max(largest, std::abs(fd));
    }
  EXPECT_GT(largest, 1e-3);
  EXPECT_LT(worst, 1e-6 * largest);
}

TEST(LpCvt, AJitteredLatticeGoesBackToTheLattice) {
  const double a = 0.5;
  const Lattice l = lattice(5, a, 0.3);
  const std::size_t n = l.ns + l.ni;
  const std::vector<Frame> frame(n, kAxes);
  const std::vector<double> size(n, a);
  double before = 0;
  for (std::size_t i = 0; i < l.ni; ++i)
    for (int d = 0; d < 3; ++d) {
      const double x = l.points[l.ns + i][d] / a;
      before = std::max(before, std::abs(x - std::round(x)));
    }
  LpCvtOptions o;
  o.iterations = 100;
  LpCvtReport r;
  const std::vector<Vec3> moved = optimize_lp_cvt(l.points, l.ns, l.ni, frame, size, o, &r);
  ASSERT_EQ(moved.size(), l.ni);
  double after = 0;
  for (const Vec3& p : moved)
    for (int d = 0; d < 3; ++d) after = std::max(after, std::abs(p[d] / a - std::round(p[d] / a)));
  EXPECT_GT(before, 0.1);
  EXPECT_LT(after, 1e-4) << r.iterations << " iterations, " << r.evaluations << " evaluations";
  EXPECT_LT(r.energy_after, r.energy_before);
}

TEST(LpCvt, AnOddExponentIsRefused) {
  const Lattice l = lattice(2, 1.0, 0.1);
  const std::vector<Frame> frame(l.ns + l.ni, kAxes);
  const std::vector<double> size(l.ns + l.ni, 1.0);
  LpCvtOptions o;
  o.iterations = 1;
  o.p = 7;
  EXPECT_ANY_THROW(optimize_lp_cvt(l.points, l.ns, l.ni, frame, size, o));
}

nlohmann::json mesh_json(const std::string& args, int threads = 2) {
  const std::string cmd = "OMP_NUM_THREADS=" + std::to_string(threads) + " " +
                          std::string(HEXFEM_BINARY) + " mesh " + HEXFEM_TEST_DATA +
                          "/Torus_1.brep --h 19.15 --json " + args + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  std::string out;
  std::array<char, 4096> buf;
  while (p && fgets(buf.data(), buf.size(), p)) out += buf.data();
  EXPECT_EQ(p ? pclose(p) : -1, 0) << out;
  return nlohmann::json::parse(out.substr(out.find('{')));
}

// The torus at diagonal / 60: a valid mesh whose volume is the default mesh's (both lie below
// the CAD's by the chords of the curved surface), the energy lowered, most moves kept, and the
// same bytes for 1 and 2 threads.
TEST(LpCvt, TorusMeshesValidAndTheSameForOneAndTwoThreads) {
  const std::string work = HEXFEM_WORK_DIR;
  const double base_volume = mesh_json("-o " + work + "/torus_default.msh")["mesh_volume"];
  std::string files[2];
  for (int threads = 1; threads <= 2; ++threads) {
    files[threads - 1] = work + "/torus_lpcvt_" + std::to_string(threads) + ".msh";
    const nlohmann::json j =
        mesh_json("--smooth-frame --lp-cvt 5 -o " + files[threads - 1], threads);
    EXPECT_EQ(j["inverted"], 0);
    EXPECT_NEAR(j["mesh_volume"].get<double>(), base_volume, 8e-4 * base_volume);
    EXPECT_EQ(j["lp_cvt"]["iterations"], 5);
    EXPECT_LT(j["lp_cvt"]["energy_after"].get<double>(),
              j["lp_cvt"]["energy_before"].get<double>());
    EXPECT_GT(j["lp_cvt"]["moves_kept"].get<double>(), 0.9 * j["interior_points"].get<double>());
  }
  EXPECT_EQ(cadtest::file_bytes(files[0]), cadtest::file_bytes(files[1]));
}

}  // namespace
}  // namespace hexfem
