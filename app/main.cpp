// hexfem: CAD part -> hex-dominant mesh -> natural frequencies.
#include <algorithm>
#include <cstdio>
#include <exception>
#include <new>

#include "app/command_registry.hpp"
#include "mesher/mesh/error.hpp"

namespace hexfem {
std::vector<CommandSpec>& command_registry() {
  static std::vector<CommandSpec> registry;
  return registry;
}
}  // namespace hexfem

int main(int argc, char** argv) {
  using namespace hexfem;
  CLI::App app{
      "hexfem: hex-dominant meshes of CAD parts (Baudouin et al. 2014) and their natural "
      "frequencies"};
  app.set_version_flag("--version", std::string("hexfem ") + HEXFEM_VERSION);
  app.require_subcommand(1);

  auto& registry = command_registry();
  std::sort(registry.begin(), registry.end(),
            [](const CommandSpec& a, const CommandSpec& b) { return a.name < b.name; });
  std::function<int()> action;
  for (auto& spec : registry) {
    CLI::App* sub = app.add_subcommand(spec.name, spec.description);
    auto run = std::make_shared<std::function<int()>>();
    *run = spec.setup(*sub);
    sub->callback([run, &action] { action = *run; });
  }

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  try {
    return action ? action() : 1;
  } catch (const Error& e) {
    std::fprintf(stderr, "hexfem: error: %s\n", e.what());
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "hexfem: error: out of memory\n");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hexfem: error: %s\n", e.what());
  }
  return 1;
}
