// Isotropic linear-elastic material, SI units (Pa, kg/m^3).
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace hexfem {

struct Material {
  std::string name = "custom";
  double E = 0;    // Young's modulus [Pa]
  double nu = 0;   // Poisson's ratio
  double rho = 0;  // density [kg/m^3]

  double lambda() const { return E * nu / ((1 + nu) * (1 - 2 * nu)); }
  double mu() const { return E / (2 * (1 + nu)); }
};

// Throws hexfem::Error naming the bad value: E <= 0, rho <= 0, nu outside (-1, 0.5).
void validate(const Material& m);

// The material of each CAD solid (MixedMesh::cell_solid): an assembly of steel bolts in an
// aluminium housing. Cells of a solid listed in by_solid take its material, all others `base`.
// Implicit from one Material: every solid alike.
struct SolidMaterials {
  Material base;
  std::vector<std::pair<std::int32_t, Material>> by_solid;  // sorted by solid id, ids unique

  SolidMaterials() = default;
  SolidMaterials(Material m) : base(std::move(m)) {}  // NOLINT: one material for every solid
  const Material& of(std::int32_t solid) const;
  // One entry per solid id up to the largest listed (and at least max_solid): a lookup table for
  // the per-cell loops; ids not listed point to base.
  std::vector<const Material*> table(std::int32_t max_solid) const;
};

// validate() of each material; throws hexfem::Error naming the solid whose material is bad, or a
// solid id that is listed twice or is not positive.
void validate(const SolidMaterials& m);

// Named materials: steel (210 GPa, 0.3, 7850), aluminium (70 GPa, 0.33, 2700),
// titanium (114 GPa, 0.34, 4430). Unknown name: hexfem::Error listing the names.
Material material_by_name(const std::string& name);

}  // namespace hexfem
