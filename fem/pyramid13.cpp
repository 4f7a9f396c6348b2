// Pyramid13 with the rational basis of Bedrosian (1992, "Shape functions and integration formulas
// for three-dimensional finite element analysis", IJNME 35:95-108), as in libMesh's PYRAMID13:
// base (±1,±1,0), apex (0,0,1), d = 1-ζ. For a base corner (a,b):
//   N = (aξ+bη-1)(d+aξ)(d+bη) / (4d);
// base mid-edge (0,b): (d+ξ)(d-ξ)(d+bη)/(2d), and (a,0) likewise; vertical mid-edge below corner
// (a,b): ζ(d+aξ)(d+bη)/d; apex ζ(2ζ-1). Quad8 serendipity on the base (matches a hex20 face),
// tri6 on the sides (matches a tet10 face). In collapsed coordinates ξ = r d, η = s d every
// function and every physical gradient is a polynomial in (r, s, ζ).
#include "fem/element.hpp"
#include "mesher/mesh/element_topology.hpp"

namespace hexfem {

namespace {
constexpr double kBase[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};

// A factor c + g · (ξ, η, ζ): its value and gradient.
struct Factor {
  double v, g[3];
};
// N = scale f0 f1 f2 / d and its gradient.
void product(const Factor (&f)[3], double scale, double d, double& N, double* dN) {
  const double inv = 1 / d, prod = f[0].v * f[1].v * f[2].v;
  N = scale * prod * inv;
  for (int c = 0; c < 3; ++c)
    dN[c] =
        scale * inv *
        (f[0].g[c] * f[1].v * f[2].v + f[0].v * f[1].g[c] * f[2].v + f[0].v * f[1].v * f[2].g[c]);
  dN[2] += scale * prod * inv * inv;  // d(1/d)/dζ = 1/d²
}
}  // namespace

void pyramid13_shape(const Vec3& xi, ShapeValues& s) {
  const double x = xi[0], y = xi[1], z = xi[2], d = 1 - z;
  s.n = 13;
  for (int i = 0; i < 4; ++i) {
    const double a = kBase[i][0], b = kBase[i][1];
    const Factor f[3] = {
        {a * x + b * y - 1, {a, b, 0}}, {d + a * x, {a, 0, -1}}, {d + b * y, {0, b, -1}}};
    product(f, 0.25, d, s.N[i], s.dN[i]);
  }
  s.N[4] = z * (2 * z - 1);
  s.dN[4][0] = s.dN[4][1] = 0;
  s.dN[4][2] = 4 * z - 1;
  const auto& edges = edges_of(CellKind::Pyramid5);
  for (int e = 0; e < 8; ++e) {
    const int i = 5 + e, p = edges[e][0], q = edges[e][1];
    if (q == 4) {  // vertical edge below corner p
      const double a = kBase[p][0], b = kBase[p][1];
      const Factor f[3] = {{z, {0, 0, 1}}, {d + a * x, {a, 0, -1}}, {d + b * y, {0, b, -1}}};
      product(f, 1.0, d, s.N[i], s.dN[i]);
    } else if (kBase[p][0] == kBase[q][0]) {  // base edge at ξ = a
      const double a = kBase[p][0];
      const Factor f[3] = {{d + y, {0, 1, -1}}, {d - y, {0, -1, -1}}, {d + a * x, {a, 0, -1}}};
      product(f, 0.5, d, s.N[i], s.dN[i]);
    } else {  // base edge at η = b
      const double b = kBase[p][1];
      const Factor f[3] = {{d + x, {1, 0, -1}}, {d - x, {-1, 0, -1}}, {d + b * y, {0, b, -1}}};
      product(f, 0.5, d, s.N[i], s.dN[i]);
    }
  }
}

// Collapsed 3x3 Gauss-Legendre x 3-point Gauss-Jacobi(2,0): in (r, s, ζ) the mass integrand has
// degree <= 4 in each variable once the d² of dV is taken by the Jacobi weight, the stiffness
// as well, so both are exact on an affine pyramid. The apex is never sampled.
QuadRule pyramid13_rule() {
  return pyramid_rule(3);
}

}  // namespace hexfem
