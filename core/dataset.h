// Image sequences: the one Dataset interface every reader implements, and OpenDataset, which
// detects the format of a folder and opens it. Formats (docs/datasets.md):
//   tum       TUM RGB-D / ICL-NUIM in TUM layout: rgb.txt, optional depth.txt, groundtruth.txt,
//             camera.yaml (or a preset / file given in DatasetOptions::camera).
//   tum_mono  TUM monoVO: images/ or images.zip, times.txt, camera.txt, pcalib.txt,
//             vignette.png.
//   euroc     EuRoC MAV: mav0/cam0/data.csv, mav0/cam0/sensor.yaml, ground truth from
//             mav0/state_groundtruth_estimate0/data.csv.
//   kitti     KITTI odometry: image_0/, times.txt, calib.txt, optional poses.
// Every reader yields undistorted float images (photometrically corrected where the dataset
// ships a calibration) of one ideal pinhole camera, and ground truth as world_from_cam of that
// camera.
#ifndef PLDVO_CORE_DATASET_H_
#define PLDVO_CORE_DATASET_H_

#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "core/pinhole_camera.h"
#include "core/trajectory_io.h"

namespace pldvo {

struct Frame {
  int index = 0;
  double timestamp = 0.0;  // seconds, as the dataset gives them
  // CV_32F gray, intensities on the 0..255 scale, undistorted to Dataset::camera(),
  // photometrically corrected where calibration exists (then values may exceed 255 where the
  // vignette is below 1).
  cv::Mat image;
  std::string path;          // the image file ("archive.zip:entry" for images in a zip)
  std::string depth_path;    // tum: the depth image associated within 0.02 s, else empty
  double exposure_ms = 0.0;  // tum_mono: exposure time from times.txt, else 0 (unknown)
};

struct DatasetOptions {
  // "auto" detects the format from the folder's contents; otherwise one of DatasetFormats().
  std::string format = "auto";
  // A preset name (tum_fr1 | tum_fr2 | tum_fr3) or a camera.yaml path; overrides the
  // calibration found in the folder. Empty: the folder's own calibration.
  std::string camera = "";
  // A ground-truth file overriding the one found with the dataset: KITTI poses (12 numbers a
  // line, one line per frame) for kitti, TUM format (world_from_cam) for the other formats.
  std::string ground_truth = "";
  // tum_mono with a response calibration (pcalib.txt) and exposure times: each image is scaled by
  // t_ref / t_i (t_ref the median exposure of the sequence), so that frames of one scene have
  // one brightness whatever the auto-exposure did (DSO's model I = t B).
  bool normalize_exposure = true;

  template <class Visitor>
  void VisitFields(Visitor& v) {
    v.Field("format", &format,
            "Dataset format: auto | tum | tum_mono | euroc | kitti (auto detects it from the "
            "folder's contents).");
    v.Field("camera", &camera,
            "Camera preset (tum_fr1 | tum_fr2 | tum_fr3) or camera.yaml path overriding the "
            "folder's calibration; empty uses the folder's.");
    v.Field("ground_truth", &ground_truth,
            "Ground-truth file overriding the dataset's (KITTI poses for kitti, TUM format "
            "otherwise); empty uses the dataset's own.");
    v.Field("normalize_exposure", &normalize_exposure,
            "tum_mono with pcalib.txt and exposure times in times.txt: scale each image by the "
            "median exposure over its own (irradiance on one scale for every frame); false keeps "
            "G^-1(I) / V.");
  }
  // "" when valid, otherwise what is wrong.
  std::string Check() const;
};

class Dataset {
 public:
  virtual ~Dataset() = default;
  // One of DatasetFormats().
  virtual std::string format() const = 0;
  virtual int size() const = 0;
  // Timestamp of frame i in seconds, without loading it.
  virtual double timestamp(int i) const = 0;
  // Loads frame i (0 <= i < size(), else std::out_of_range). Throws std::runtime_error naming the
  // image file when it is missing, unreadable or of the wrong size. Safe to call from several
  // threads.
  virtual Frame Load(int i) const = 0;
  // The depth image of frame i as CV_32F metres (0 = no measurement), undistorted to camera()
  // like the image; empty when the dataset has no depth for the frame (only the tum format has
  // depth). Throws std::runtime_error naming the file when it is unreadable, not a 16-bit image
  // or of the wrong size.
  virtual cv::Mat LoadDepth(int /*i*/) const { return cv::Mat(); }
  // The undistorted pinhole camera of the images Load returns.
  virtual const PinholeCamera& camera() const = 0;
  // Camera-to-world (world_from_cam) poses of the camera() frame, or nullptr when the dataset
  // has none. Its timestamps need not coincide with the frames' (e.g. TUM's 100 Hz ground truth).
  virtual const Trajectory* ground_truth() const = 0;
};

// The format names OpenDataset accepts besides "auto".
const std::vector<std::string>& DatasetFormats();

// The format of a folder, detected from its contents (first match in this order):
//   euroc     mav0/cam0/data.csv (or cam0/data.csv when dir is the mav0 folder)
//   kitti     calib.txt, times.txt and image_0/
//   tum_mono  times.txt and images/ or images.zip
//   tum       rgb.txt
// Throws std::runtime_error saying what was looked for in which folder when none matches.
std::string DetectDatasetFormat(const std::string& dir);

// Opens a dataset folder. Throws std::runtime_error (naming the file and line where one is at
// fault) when the folder is not a dataset of the format, a file is malformed, the calibration is
// unusable or the sequence is empty.
std::unique_ptr<Dataset> OpenDataset(const std::string& dir, const DatasetOptions& options = {});

}  // namespace pldvo

#endif  // PLDVO_CORE_DATASET_H_
