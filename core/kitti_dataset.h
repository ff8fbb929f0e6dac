// KITTI odometry (format "kitti"): image_0/, times.txt, calib.txt (P0), optional poses.
// See docs/datasets.md.
#ifndef PLDVO_CORE_KITTI_DATASET_H_
#define PLDVO_CORE_KITTI_DATASET_H_

#include <memory>
#include <string>

#include "core/dataset.h"

namespace pldvo {

// Throws std::runtime_error naming the file (and line) at fault.
std::unique_ptr<Dataset> OpenKittiDataset(const std::string& dir, const DatasetOptions& options);

}  // namespace pldvo

#endif  // PLDVO_CORE_KITTI_DATASET_H_
