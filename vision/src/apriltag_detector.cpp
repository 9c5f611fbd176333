#include "apriltag_detector.h"

#include <apriltag.h>
#include <tag16h5.h>
#include <tag25h9.h>
#include <tag36h10.h>
#include <tag36h11.h>
#include <tagCircle21h7.h>
#include <tagCircle49h12.h>
#include <tagCustom48h12.h>
#include <tagStandard41h12.h>
#include <tagStandard52h13.h>

#include <stdexcept>

#include "quad_fit.h"

namespace arbci::vision {
namespace {

struct Family {
  const char* name;
  const char* opencv_name;  // OpenCV's dictionary of the same family, if any
  apriltag_family_t* (*create)();
  void (*destroy)(apriltag_family_t*);
};

constexpr Family kFamilies[] = {
    {"tag36h11", "DICT_APRILTAG_36h11", tag36h11_create, tag36h11_destroy},
    {"tag36h10", "DICT_APRILTAG_36h10", tag36h10_create, tag36h10_destroy},
    {"tag25h9", "DICT_APRILTAG_25h9", tag25h9_create, tag25h9_destroy},
    {"tag16h5", "DICT_APRILTAG_16h5", tag16h5_create, tag16h5_destroy},
    {"tagStandard41h12", "", tagStandard41h12_create, tagStandard41h12_destroy},
    {"tagStandard52h13", "", tagStandard52h13_create, tagStandard52h13_destroy},
    {"tagCircle21h7", "", tagCircle21h7_create, tagCircle21h7_destroy},
    {"tagCircle49h12", "", tagCircle49h12_create, tagCircle49h12_destroy},
    {"tagCustom48h12", "", tagCustom48h12_create, tagCustom48h12_destroy},
};

const Family& familyNamed(const std::string& name) {
  const std::string wanted = name.empty() ? "tag36h11" : name;
  for (const Family& f : kFamilies) {
    if (wanted == f.name || (*f.opencv_name && wanted == f.opencv_name)) return f;
  }
  throw std::invalid_argument("unknown AprilTag family '" + name + "' (libapriltag has " +
                              aprilTagFamilies() + ")");
}

}  // namespace

std::string aprilTagFamilies() {
  std::string names;
  for (const Family& f : kFamilies) names += (names.empty() ? "" : ", ") + std::string(f.name);
  return names;
}

struct AprilTagDetector::Impl {
  const Family* family = nullptr;
  apriltag_family_t* tags = nullptr;
  apriltag_detector_t* detector = nullptr;
  bool refine_edges = true;
  ~Impl() {
    if (detector) apriltag_detector_destroy(detector);
    if (tags) family->destroy(tags);
  }
};

AprilTagDetector::AprilTagDetector(const std::string& family, bool refine_edges, int decimate)
    : impl_(std::make_unique<Impl>()) {
  impl_->family = &familyNamed(family);
  impl_->tags = impl_->family->create();
  impl_->detector = apriltag_detector_create();
  if (!impl_->tags || !impl_->detector)
    throw std::runtime_error("libapriltag could not create its detector");
  apriltag_detector_add_family(impl_->detector, impl_->tags);
  impl_->detector->quad_decimate = static_cast<float>(decimate);
  impl_->detector->nthreads = 1;
  impl_->detector->refine_edges = false;  // see the header: refined after decoding instead
  impl_->refine_edges = refine_edges;
}

AprilTagDetector::~AprilTagDetector() = default;

std::vector<MarkerDetection> AprilTagDetector::detect(const cv::Mat& gray) {
  CV_Assert(gray.type() == CV_8UC1);
  image_u8_t image{gray.cols, gray.rows, static_cast<int32_t>(gray.step), gray.data};
  zarray_t* detections = apriltag_detector_detect(impl_->detector, &image);
  std::vector<MarkerDetection> out;
  for (int i = 0; i < zarray_size(detections); ++i) {
    apriltag_detection_t* d = nullptr;
    zarray_get(detections, i, &d);
    MarkerDetection m;
    m.id = d->id;
    m.kind = MarkerKind::AprilTag;
    // libapriltag's corners are the tag frame's (-1,1), (1,1), (1,-1), (-1,-1): on the tag as
    // printed (its own canonical image, apriltag_to_image) p[3] is the top-left, and the four
    // wrap counter-clockwise; ours start top-left and go clockwise. (OpenCV's DICT_APRILTAG_*
    // reads the printed tag rotated 180 degrees: its first corner is the printed bottom-right.)
    // Its pixel centres sit at +0.5 of OpenCV's.
    for (int k = 0; k < 4; ++k) {
      const double* p = d->p[3 - k];
      m.corners[k] = cv::Point2f(static_cast<float>(p[0] - 0.5), static_cast<float>(p[1] - 0.5));
    }
    if (impl_->refine_edges) {
      QuadFitParams params;
      params.min_side = 4.0f;
      // Kept as libapriltag placed them when the sides cannot be moved onto edges.
      if (const auto refined = refineQuad(m.corners, gray, params)) m.corners = refined->corners;
    }
    m.ideal_corners = m.corners;
    m.corrected_bits = d->hamming;
    m.confidence = 1.0f / (1.0f + static_cast<float>(d->hamming));
    out.push_back(m);
  }
  apriltag_detections_destroy(detections);
  return out;
}

}  // namespace arbci::vision
