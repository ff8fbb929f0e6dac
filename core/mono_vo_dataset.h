// TUM monoVO (format "tum_mono"): images/ or images.zip, times.txt, camera.txt (FOV model,
// DSO's conventions), optional pcalib.txt and vignette.png.
// See docs/datasets.md.
#ifndef PLDVO_CORE_MONO_VO_DATASET_H_
#define PLDVO_CORE_MONO_VO_DATASET_H_

#include <memory>
#include <string>

#include "core/dataset.h"

namespace pldvo {

// Throws std::runtime_error naming the file (and line) at fault.
std::unique_ptr<Dataset> OpenMonoVoDataset(const std::string& dir, const DatasetOptions& options);

}  // namespace pldvo

#endif  // PLDVO_CORE_MONO_VO_DATASET_H_
