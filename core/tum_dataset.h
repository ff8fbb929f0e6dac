// TUM RGB-D / ICL-NUIM in TUM layout (format "tum"): rgb.txt, optional depth.txt and
// groundtruth.txt, camera.yaml or DatasetOptions::camera.
// See docs/datasets.md.
#ifndef PLDVO_CORE_TUM_DATASET_H_
#define PLDVO_CORE_TUM_DATASET_H_

#include <memory>
#include <string>

#include "core/dataset.h"

namespace pldvo {

// Throws std::runtime_error naming the file (and line) at fault.
std::unique_ptr<Dataset> OpenTumDataset(const std::string& dir, const DatasetOptions& options);

}  // namespace pldvo

#endif  // PLDVO_CORE_TUM_DATASET_H_
