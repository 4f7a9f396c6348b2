#include "fem/material.hpp"

#include <algorithm>
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

const Material& SolidMaterials::of(std::int32_t solid) const {
  const auto it = std::lower_bound(
      by_solid.begin(), by_solid.end(), solid,
      [](const std::pair<std::int32_t, Material>& e, std::int32_t s) { return e.first < s; });
  return it != by_solid.end() && it->first == solid ? it->second : base;
}

std::vector<const Material*> SolidMaterials::table(std::int32_t max_solid) const {
  std::int32_t n = std::max<std::int32_t>(max_solid, 0);
  if (!by_solid.empty()) n = std::max(n, by_solid.back().first);
  std::vector<const Material*> t(static_cast<std::size_t>(n) + 1, &base);
  for (const auto& [solid, m] : by_solid) t[static_cast<std::size_t>(solid)] = &m;
  return t;
}

void validate(const SolidMaterials& m) {
  validate(m.base);
  for (std::size_t i = 0; i < m.by_solid.size(); ++i) {
    const std::int32_t solid = m.by_solid[i].first;
    if (solid < 1) throw Error("solid ids start at 1 (got " + std::to_string(solid) + ")");
    if (i > 0 && m.by_solid[i - 1].first >= solid)
      throw Error("solid " + std::to_string(solid) + " is given two materials");
    try {
      validate(m.by_solid[i].second);
    } catch (const Error& e) {
      throw Error("material of solid " + std::to_string(solid) + ": " + e.what());
    }
  }
}

Material material_by_name(const std::string& name) {
  if (name == "steel") return {"steel", 210e9, 0.3, 7850};
  if (name == "aluminium" || name == "aluminum") return {"aluminium", 70e9, 0.33, 2700};
  if (name == "titanium") return {"titanium", 114e9, 0.34, 4430};
  throw Error("unknown material '" + name + "' (known: steel, aluminium, titanium)");
}

}  // namespace hexfem
