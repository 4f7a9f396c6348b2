// Shared helpers for the fem tests: reference cells, random affine maps and distortions.
#pragma once

#include <sys/wait.h>

#include <Eigen/Dense>
#include <array>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "fem/assembly.hpp"
#include "mesher/mesh/mixed_mesh.hpp"

namespace hexfem::test {

// A shell command's exit code and its stdout and stderr together.
struct CliRun {
  int code;
  std::string out;
};

inline CliRun run_command(const std::string& command) {
  const std::string cmd = command + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  CliRun r{-1, ""};
  if (!p) return r;
  std::array<char, 4096> buf;
  while (fgets(buf.data(), buf.size(), p)) r.out += buf.data();
  const int status = pclose(p);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

inline std::vector<Vec3> reference_corners(CellKind kind) {
  switch (kind) {
    case CellKind::Hex8:
      return {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1},
              {-1, -1, 1},  {1, -1, 1},  {1, 1, 1},  {-1, 1, 1}};
    case CellKind::Wedge6:
      return {{0, 0, -1}, {1, 0, -1}, {0, 1, -1}, {0, 0, 1}, {1, 0, 1}, {0, 1, 1}};
    case CellKind::Pyramid5:
      return {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}, {0, 0, 1}};
    case CellKind::Tet4:
      return {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  }
  return {};
}

inline constexpr CellKind kAllKinds[] = {CellKind::Tet4, CellKind::Pyramid5, CellKind::Wedge6,
                                         CellKind::Hex8};

// x -> A x + b with a random well-conditioned A of positive determinant.
inline std::vector<Vec3> affine_image(const std::vector<Vec3>& ref, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-0.3, 0.3);
  Eigen::Matrix3d A = Eigen::Matrix3d::Identity() * 0.7;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) A(i, j) += u(rng);
  const Eigen::Vector3d b(u(rng), u(rng), u(rng));
  std::vector<Vec3> out;
  for (const Vec3& p : ref) {
    const Eigen::Vector3d y = A * Eigen::Vector3d(p[0], p[1], p[2]) + b;
    out.push_back({y[0], y[1], y[2]});
  }
  return out;
}

// Every coordinate moved by up to `amount` (absolute).
inline void perturb(std::vector<Vec3>& x, double amount, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-amount, amount);
  for (Vec3& p : x)
    for (double& c : p) c += u(rng);
}

// Dense full matrix from an assembled lower triangle.
inline Eigen::MatrixXd dense_full(const SparseMatrix& lower) {
  const SparseMatrix full = lower.selfadjointView<Eigen::Lower>();
  return Eigen::MatrixXd(full);
}

}  // namespace hexfem::test
