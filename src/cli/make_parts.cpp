// make_parts: writes the STL parts of the shipped conformal scenarios (scenarios/shembekar_*.stl)
// from the project's own analytic surfaces (toolpath/analytic_surfaces.hpp), byte for byte the
// same on every run. Shapes after Shembekar et al. 2018, Table 1 and Fig. 4:
//   shembekar_beam.stl    specimen A: a 65 x 14 mm curved beam, 6 mm sag, 4 mm thick
//   shembekar_bonnet.stl  specimen D-like: a 150 x 130 mm bonnet with a rolled front edge
//   shembekar_fillet.stl  the Fig. 4 case: a step with small-radius fillets
// usage: make_parts [DIR]   (default: the source tree's scenarios/)
#include <cstdio>
#include <exception>
#include <filesystem>
#include <string>

#include "toolpath/analytic_surfaces.hpp"
#include "toolpath/stl.hpp"

int main(int argc, char** argv) {
  using namespace depotwin;
  const std::string directory = argc > 1 ? argv[1] : DEPOTWIN_SCENARIOS_DIR;
  try {
    std::filesystem::create_directories(directory);
    const auto write = [&](const TriangleMesh& mesh, const std::string& name,
                           const std::string& header) {
      const std::string path = directory + "/" + name;
      write_stl_binary(mesh, path, header);
      std::printf("make_parts: %s, %zu triangles\n", path.c_str(), mesh.triangle_count());
    };
    // the beam's arch (radius 91 mm) needs no 0.5 mm cells: 1 mm cells keep the chordal
    // error at 0.0014 mm and the file small
    CurvedBeamParams beam;
    beam.mesh.cell_mm = 1.0;
    write(curved_beam(beam), "shembekar_beam.stl",
          "DepoTwin make_parts: curved beam 65 x 14 mm, sag 6 mm, 4 mm thick (mm)");
    write(car_bonnet(CarBonnetParams{}), "shembekar_bonnet.stl",
          "DepoTwin make_parts: bonnet 150 x 130 mm, rolled front edge (mm)");
    // the fillet step 12 mm wide: two dozen hatch lines are enough to see the blob
    FilletStepParams fillet;
    fillet.width_mm = 12.0;
    write(fillet_step(fillet), "shembekar_fillet.stl",
          "DepoTwin make_parts: step 12 mm wide, 2 mm fillets, 40 deg slope (mm)");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "make_parts: %s\n", e.what());
    return 1;
  }
  return 0;
}
