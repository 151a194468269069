// Writes the seeds a fuzzer cannot be given by hand: design files (`vibid dob design` for the
// nominal rig, SISO with a displacement sensor and MIMO with accelerometers; they carry the
// board's fixed-point description and its checksum) and a UFF58 file written from the CSV seed.
// Each is prefixed with the fuzzer's mode byte.
#include <fstream>
#include <iostream>
#include <string>

#include "vibid/dob/design.hpp"
#include "vibid/dob/design_json.hpp"
#include "vibid/dob/model_plant.hpp"
#include "vibid/common/atomic_file.hpp"
#include "vibid/ident/frf_io.hpp"
#include "vibid/model/model_json.hpp"

int main(int argc, char** argv) {
  if (argc != 5) {
    std::cerr << "usage: host_fuzz_seeds MODEL.json JSON_SEEDS_DIR FRF.csv FRF_SEEDS_DIR\n";
    return 2;
  }
  using namespace vibid;
  const model::Model m = model::LoadModel(argv[1]);
  for (const bool mimo : {false, true}) {
    dob::DobOptions o;
    o.input_dof = 1;
    o.output_dof = 1;
    if (mimo) {
      o.form = dob::ObserverForm::kMimo;
      o.sensor = dob::SensorKind::kAcceleration;
    }
    const dob::DobDesign design =
        dob::DesignObserver(dob::PlantFromModel(m, o.input_dof, o.output_dof), o);
    if (!design.stable) {
      std::cerr << design.message << "\n";
      return 1;
    }
    std::ofstream out(std::string(argv[2]) + (mimo ? "/design_mimo.json" : "/design_siso.json"),
                      std::ios::binary);
    out << '\x01' << dob::DesignToJson(design).dump(1) << "\n";
  }
  const ident::Frf frf = ident::ParseFrfCsv(ReadFileText(argv[3]), argv[3]);
  std::ofstream uff(std::string(argv[4]) + "/frf.uff", std::ios::binary);
  uff << '\x01' << ident::FormatUff58(frf, 3);
  return 0;
}
