// hexfem convert in.msh out.{msh,vtu,inp} [--binary]: format from the extensions (in any case).
// A .vtu of a mesh with non-conformal quad faces comes with <out>_nc.vtu, those faces alone.
#include "app/cli_checks.hpp"
#include "app/command_registry.hpp"
#include "mesher/mesh/mesh_io.hpp"

namespace hexfem {
namespace {

RegisterCommand reg{{"convert", "Convert a mesh between formats (.msh in; .msh, .vtu, .inp out)",
                     [](CLI::App& sub) -> std::function<int()> {
                       auto in = std::make_shared<std::string>();
                       auto out = std::make_shared<std::string>();
                       auto binary = std::make_shared<bool>(false);
                       sub.add_option("input", *in, "Input mesh (.msh)")->required();
                       sub.add_option("output", *out, "Output mesh (.msh, .vtu, .inp)")->required();
                       sub.add_flag("--binary", *binary, "Write MSH 4.1 binary");
                       return [in, out, binary] {
                         check_input_file(*in);
                         check_output_file("output", *out, {"msh", "vtu", "inp"}, {*in});
                         check_binary_format(*binary, *out);
                         const MixedMesh mesh = read_mesh(*in);
                         write_mesh(mesh, *out, MshWriteOptions{*binary});
                         return 0;
                       };
                     }}};

}  // namespace
}  // namespace hexfem
