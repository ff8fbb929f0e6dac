// EuRoC MAV (format "euroc"): mav0/cam0 images with sensor.yaml, ground truth from
// mav0/state_groundtruth_estimate0 moved to the camera with T_BS.
// See docs/datasets.md.
#ifndef PLDVO_CORE_EUROC_DATASET_H_
#define PLDVO_CORE_EUROC_DATASET_H_

#include <memory>
#include <string>

#include "core/dataset.h"

namespace pldvo {

// Throws std::runtime_error naming the file (and line) at fault.
std::unique_ptr<Dataset> OpenEurocDataset(const std::string& dir, const DatasetOptions& options);

}  // namespace pldvo

#endif  // PLDVO_CORE_EUROC_DATASET_H_
