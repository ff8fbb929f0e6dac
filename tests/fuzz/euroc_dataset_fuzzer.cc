// libFuzzer target: the EuRoC MAV reader (core/euroc_dataset.h through OpenDataset, format
// "euroc"): mav0/cam0/data.csv, mav0/cam0/sensor.yaml and
// mav0/state_groundtruth_estimate0/data.csv. Input: a selector byte ('0' cam0/data.csv,
// '1' sensor.yaml, '2' ground-truth data.csv), then that file; the others hold valid defaults.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "tests/fuzz/dataset_fuzz.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace pldvo;  // NOLINT(build/namespaces)
  static const std::string dir = fuzz::ScratchDir() + "/euroc";
  static const std::vector<fuzz::FixtureFile> files = {
      {"mav0/cam0/data.csv",
       "#timestamp [ns],filename\n1403636579763555584,1403636579763555584.png\n"
       "1403636579813555456,1403636579813555456.png\n"},
      {"mav0/cam0/sensor.yaml",
       "sensor_type: camera\ncomment: VI-Sensor cam0 (MT9M034)\n\n"
       "# Sensor extrinsics wrt. the body-frame.\nT_BS:\n  cols: 4\n  rows: 4\n"
       "  data: [0.0148655429818, -0.999880929698, 0.00414029679422, -0.0216401454975,\n"
       "         0.999557249008, 0.0149672133247, 0.025715529948, -0.064676986768,\n"
       "        -0.0257744366974, 0.00375618835797, 0.999660727178, 0.00981073058949,\n"
       "         0.0, 0.0, 0.0, 1.0]\n\n"
       "# Camera specific definitions.\nrate_hz: 20\nresolution: [32, 24]\n"
       "camera_model: pinhole\nintrinsics: [30.0, 30.0, 15.5, 11.5] #fu, fv, cu, cv\n"
       "distortion_model: radial-tangential\n"
       "distortion_coefficients: [-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05]\n"},
      {"mav0/state_groundtruth_estimate0/data.csv",
       "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], "
       "q_RS_z [], v_RS_R_x [m s^-1]\n"
       "1403636580838555648,4.688319,-1.786938,0.783338,0.534108,-0.153029,-0.827383,"
       "-0.082152,-0.027876\n"
       "1403636580843555328,4.688177,-1.786770,0.787350,0.534640,-0.152990,-0.826976,"
       "-0.082863,-0.029272\n"},
  };
  return fuzz::FuzzDatasetFolder(data, size, dir, "euroc", files, /*skip_large_sizes=*/true);
}
