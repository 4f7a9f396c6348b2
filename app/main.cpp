// hexfem: CAD part -> hex-dominant mesh -> natural frequencies.
#include <algorithm>
#include <cstdio>
#include <exception>
#include <new>
#include <string>

#include "app/command_registry.hpp"
#include "fem/iterative_solver.hpp"
#include "mesher/mesh/error.hpp"
#include "mesher/mesh/progress.hpp"

namespace hexfem {
std::vector<CommandSpec>& command_registry() {
  static std::vector<CommandSpec> registry;
  return registry;
}

namespace {
// One line on stderr whatever the message holds (CLI11 and library messages may span lines).
void print_error(std::string message, const char* suffix = "") {
  end_progress();  // on a terminal, the error takes the progress line's place
  std::replace(message.begin(), message.end(), '\n', ' ');
  while (!message.empty() && message.back() == ' ') message.pop_back();
  std::fprintf(stderr, "hexfem: error: %s%s\n", message.c_str(), suffix);
}
}  // namespace
}  // namespace hexfem

int main(int argc, char** argv) {
  using namespace hexfem;
  MpiSession mpi;  // under mpirun: ranks > 0 only take part in rank 0's solves
  if (!mpi.is_root()) return mpi.serve();
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

  // CLI11 would call an unknown command "A subcommand is required": name it instead.
  if (argc > 1 && argv[1][0] != '-' &&
      std::none_of(registry.begin(), registry.end(),
                   [&](const CommandSpec& c) { return c.name == argv[1]; })) {
    std::string names;
    for (const auto& spec : registry) names += (names.empty() ? "" : ", ") + spec.name;
    print_error(std::string("unknown command '") + argv[1] + "' (commands: " + names + ")");
    return 2;
  }
  // CLI11 reads an empty value as 0 for a number (`--h ""`: "must be > 0 (got 0.000000)"); no
  // hexfem argument is empty, so one is named as such.
  for (int i = 1; i < argc; ++i)
    if (argv[i][0] == '\0') {
      print_error(i > 1 && argv[i - 1][0] == '-'
                      ? std::string("the value after ") + argv[i - 1] + " is empty"
                      : "argument " + std::to_string(i) + " is empty",
                  " (see hexfem --help)");
      return 2;
    }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version are "errors" with exit code 0: CLI11 prints them. Every real parse
    // error is one line like any other bad input (the usage is for --help).
    if (e.get_exit_code() == 0) return app.exit(e);
    print_error(e.what(), " (see hexfem --help)");
    return 2;
  }
  try {
    return action ? action() : 1;
  } catch (const std::bad_alloc&) {
    print_error("out of memory");
  } catch (const std::exception& e) {
    print_error(e.what());
  } catch (...) {
    print_error("internal error: an unexpected exception (please report the input)");
  }
  return 1;
}
