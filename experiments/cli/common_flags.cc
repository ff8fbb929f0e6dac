#include "experiments/cli/common_flags.h"

DEFINE_string(dataset, "", "Dataset folder (tum, tum_mono, euroc or kitti layout).");
DEFINE_string(format, "auto", "Dataset format: auto | tum | tum_mono | euroc | kitti.");
DEFINE_string(camera, "",
              "Camera preset (tum_fr1 | tum_fr2 | tum_fr3) or camera.yaml overriding the "
              "folder's calibration.");
DEFINE_string(config, "", "Configuration YAML (docs/configuration.md); --set overrides it.");
DEFINE_string(out, "", "Output directory (created if missing).");
DEFINE_bool(json, false, "Print one JSON object instead of the text summary.");
