// Private: pattern normalisation. The unit square (u right, v down; corner k of the quad at
// (0,0), (1,0), (1,1), (0,1)) is mapped onto the image by the quad's homography, and the marker is
// read in those coordinates: the 6x6 code cells, its black border and the white surround. Black
// and white levels are planes fitted across the marker, so a cell's threshold follows a lighting
// gradient.
#pragma once

#include <array>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "quad_fit.h"

namespace arbci::vision {

// Projective map of the unit square onto a quad (Heckbert's square-to-quad mapping).
class SquareToQuad {
 public:
  explicit SquareToQuad(const std::array<cv::Point2f, 4>& corners);
  cv::Point2f operator()(double u, double v) const;
  // The image points of four (u[i], v[i]) and the map's partial derivatives there (px per unit).
  struct Four {
    float x[4], y[4], du_x[4], du_y[4], dv_x[4], dv_y[4];
  };
  void withDerivatives(const double (&u)[4], const double (&v)[4], Four& out) const;
  // True when the square [low, high]^2 lies wholly on the finite side of the vanishing line.
  bool finiteOn(double low, double high) const;

 private:
  double a_, b_, c_, d_, e_, f_, g_, h_;
};

struct MarkerSamples {
  std::array<float, 36> cells{};       // mean intensity of each code cell, row-major
  std::array<float, 36> thresholds{};  // the black/white midpoint at each cell
  float contrast = 0;                  // white minus black level at the marker's centre
  int border_samples = 0;
  int border_light = 0;           // border samples lighter than their local threshold
  float lowest = 0, highest = 0;  // extremes of the code cells
  // Median of the marker's pixels: of its black border and white surround samples, equally many.
  float median = 0;
};

// `border` is the border width as a fraction of the side (0.125 thin, 0.25 standard).
MarkerSamples sampleMarker(const cv::Mat& image, const Quad& quad, double border);

// True when the code area of the quad with `corners` is one flat level although the quad is
// clearly darker than its surround: a solid dark shape. No BCH marker is: every BCH codeword has
// at least 7 cells of each colour. Single samples, cheap enough to run before a quad is refined
// (a pixel's error in the corners does not make a marker's cells flat).
bool hasFlatCodeArea(const cv::Mat& image, const std::array<cv::Point2f, 4>& corners,
                     double border);

// An n x n grid of mean intensities over the code area [border, 1 - border]^2 (template patterns).
std::vector<float> sampleCodeArea(const cv::Mat& image, const Quad& quad, double border, int n);

}  // namespace arbci::vision
