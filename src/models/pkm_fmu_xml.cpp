// Build tool: writes every model description from the variable tables.
//   pkm_fmu_xml <directory>   writes <directory>/fmi2/<model>.xml and <directory>/fmi3/<model>.xml
// CMake runs it into the build tree; a test compares the result with the
// committed modelDescription/ (the target update_model_descriptions copies
// it there).
#include <cstdio>
#include <fstream>
#include <string>

#include "model_description.hpp"
#include "models.hpp"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s <directory>\n", argv[0]);
    return 2;
  }
  const pkm_fmi::ModelDefinition* defs[] = {&pkm_fmi::pkm4puu_definition(), &pkm_fmi::pkm4puu_inverse_definition()};
  for (int version : {2, 3}) {
    for (const auto* d : defs) {
      const std::string path = std::string(argv[1]) + "/fmi" + std::to_string(version) + "/" + d->identifier + ".xml";
      std::ofstream out(path, std::ios::binary);
      out << pkm_fmi::model_description_xml(*d, version);
      out.close();
      if (!out) {
        std::fprintf(stderr, "%s: cannot write %s (does the directory exist?)\n", argv[0], path.c_str());
        return 1;
      }
    }
  }
  return 0;
}
