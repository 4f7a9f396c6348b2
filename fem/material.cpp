#include "fem/material.hpp"

#include <cmath>
#include <sstream>

#include "mesher/mesh/error.hpp"

namespace hexfem {

void validate(const Material& m) {
  std::ostringstream msg;
  if (!std::isfinite(m.E) || m.E <= 0)
    msg << "Young's modulus E must be positive (got " << m.E << " Pa)";
  else if (!std::isfinite(m.rho) || m.rho <= 0)
    msg << "density rho must be positive (got " << m.rho << " kg/m^3)";
  else if (!std::isfinite(m.nu) || m.nu <= -1 || m.nu >= 0.5)
    msg << "Poisson's ratio nu must be in (-1, 0.5) (got " << m.nu << ")";
  else
    return;
  throw Error(msg.str());
}

Material material_by_name(const std::string& name) {
  if (name == "steel") return {"steel", 210e9, 0.3, 7850};
  if (name == "aluminium" || name == "aluminum") return {"aluminium", 70e9, 0.33, 2700};
  if (name == "titanium") return {"titanium", 114e9, 0.34, 4430};
  throw Error("unknown material '" + name + "' (known: steel, aluminium, titanium)");
}

}  // namespace hexfem
