// hexfem convert in.msh out.{msh,vtu,inp} [--binary]: format from the extensions.
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
                         const MixedMesh mesh = read_mesh(*in);
                         write_mesh(mesh, *out, MshWriteOptions{*binary});
                         return 0;
                       };
                     }}};

}  // namespace
}  // namespace hexfem
