// Isotropic linear-elastic material, SI units (Pa, kg/m^3).
#pragma once

#include <string>

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

// Named materials: steel (210 GPa, 0.3, 7850), aluminium (70 GPa, 0.33, 2700),
// titanium (114 GPa, 0.34, 4430). Unknown name: hexfem::Error listing the names.
Material material_by_name(const std::string& name);

}  // namespace hexfem
