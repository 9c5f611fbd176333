#include "marker_sampler.h"

#include <algorithm>
#include <cmath>

#include "image_sampling.h"

namespace arbci::vision {
namespace {

// Least-squares plane level(u, v) = p0 + p1 u + p2 v.
struct Plane {
  double p0 = 0, p1 = 0, p2 = 0;
  double at(double u, double v) const { return p0 + p1 * u + p2 * v; }
};

Plane fitPlane(const cv::Point3d* samples, int count) {
  double s[3][3] = {}, r[3] = {};
  for (int n = 0; n < count; ++n) {
    const cv::Point3d& p = samples[n];
    const double basis[3] = {1.0, p.x, p.y};
    for (int i = 0; i < 3; ++i) {
      r[i] += basis[i] * p.z;
      for (int j = 0; j < 3; ++j) s[i][j] += basis[i] * basis[j];
    }
  }
  // Cramer's rule on the 3x3 normal equations.
  auto det3 = [](const double m[3][3]) {
    return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
           m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
  };
  const double det = det3(s);
  if (std::abs(det) < 1e-12) {
    double mean = 0;
    for (int n = 0; n < count; ++n) mean += samples[n].z;
    return {count == 0 ? 0.0 : mean / count, 0, 0};
  }
  double solution[3];
  for (int k = 0; k < 3; ++k) {
    double m[3][3];
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) m[i][j] = j == k ? r[i] : s[i][j];
    }
    solution[k] = det3(m) / det;
  }
  return {solution[0], solution[1], solution[2]};
}

// Means of five samples at four points (u[i], v[i]): each point and the corners of a square
// +-`spread` (unit-square units) around it. The corners are placed through the map's derivative
// at the point: a quarter cell is small enough for the projective map to be linear across it
// (well under 0.01 px off), and one map evaluation instead of five is most of the sampling's cost.
void sampleAreas(const BilinearSampler& sample, const SquareToQuad& map, const double (&u)[4],
                 const double (&v)[4], double spread, float* out) {
  SquareToQuad::Four at;
  map.withDerivatives(u, v, at);
  const float s = static_cast<float>(spread);
  float ax[4], ay[4], bx[4], by[4];  // towards (+1, +1) and (+1, -1)
  for (int i = 0; i < 4; ++i) {
    ax[i] = s * (at.du_x[i] + at.dv_x[i]);
    ay[i] = s * (at.du_y[i] + at.dv_y[i]);
    bx[i] = s * (at.du_x[i] - at.dv_x[i]);
    by[i] = s * (at.du_y[i] - at.dv_y[i]);
  }
  sample.cross4(at.x, at.y, ax, ay, bx, by, out);
  for (int i = 0; i < 4; ++i) out[i] /= 5.0f;
}

// The centres of cells first .. first + 3 (row-major) of an n x n grid over [border, 1 -
// border]^2; past the grid's last cell, copies of it.
void gridCentres(int first, int n, double border, double (&u)[4], double (&v)[4]) {
  const double cell = (1.0 - 2.0 * border) / n;
  for (int i = 0; i < 4; ++i) {
    const int index = std::min(first + i, n * n - 1);
    u[i] = border + cell * (index % n + 0.5);
    v[i] = border + cell * (index / n + 0.5);
  }
}

// Single samples at four points of the marker (u[i], v[i]).
void samplesAt(const BilinearSampler& sample, const SquareToQuad& map, const double (&u)[4],
               const double (&v)[4], float* out) {
  float x[4], y[4];
  for (int i = 0; i < 4; ++i) {
    const cv::Point2f p = map(u[i], v[i]);
    x[i] = p.x;
    y[i] = p.y;
  }
  sample.four(x, y, out);
}

// Where the square [low, high]^2 of marker coordinates lands in the image (a convex region when
// the map's vanishing line stays outside it), plus a pixel for interpolation; an empty rectangle
// (so every sample is clamped) when the map degenerates there.
cv::Rect2f regionOf(const SquareToQuad& map, double low, double high) {
  const std::array<cv::Point2f, 4> corners{map(low, low), map(high, low), map(high, high),
                                           map(low, high)};
  if (!map.finiteOn(low, high)) return {-1.0f, -1.0f, 0.0f, 0.0f};
  return boundsOf(corners, 1.0f);
}

}  // namespace

SquareToQuad::SquareToQuad(const std::array<cv::Point2f, 4>& q) {
  const double x0 = q[0].x, y0 = q[0].y, x1 = q[1].x, y1 = q[1].y;
  const double x2 = q[2].x, y2 = q[2].y, x3 = q[3].x, y3 = q[3].y;
  const double sx = x0 - x1 + x2 - x3, sy = y0 - y1 + y2 - y3;
  if (std::abs(sx) < 1e-9 && std::abs(sy) < 1e-9) {
    a_ = x1 - x0;
    b_ = x3 - x0;
    d_ = y1 - y0;
    e_ = y3 - y0;
    g_ = h_ = 0;
  } else {
    const double dx1 = x1 - x2, dx2 = x3 - x2, dy1 = y1 - y2, dy2 = y3 - y2;
    const double den = dx1 * dy2 - dx2 * dy1;
    g_ = (sx * dy2 - dx2 * sy) / den;
    h_ = (dx1 * sy - sx * dy1) / den;
    a_ = x1 - x0 + g_ * x1;
    b_ = x3 - x0 + h_ * x3;
    d_ = y1 - y0 + g_ * y1;
    e_ = y3 - y0 + h_ * y3;
  }
  c_ = x0;
  f_ = y0;
}

bool SquareToQuad::finiteOn(double low, double high) const {
  for (double u : {low, high}) {
    for (double v : {low, high}) {
      if (g_ * u + h_ * v + 1.0 <= 1e-6) return false;
    }
  }
  return true;
}

void SquareToQuad::withDerivatives(const double (&u)[4], const double (&v)[4], Four& out) const {
  for (int i = 0; i < 4; ++i) {
    const double w = 1.0 / (g_ * u[i] + h_ * v[i] + 1.0);
    const double x = (a_ * u[i] + b_ * v[i] + c_) * w, y = (d_ * u[i] + e_ * v[i] + f_) * w;
    out.x[i] = static_cast<float>(x);
    out.y[i] = static_cast<float>(y);
    out.du_x[i] = static_cast<float>((a_ - x * g_) * w);
    out.du_y[i] = static_cast<float>((d_ - y * g_) * w);
    out.dv_x[i] = static_cast<float>((b_ - x * h_) * w);
    out.dv_y[i] = static_cast<float>((e_ - y * h_) * w);
  }
}

cv::Point2f SquareToQuad::operator()(double u, double v) const {
  const double w = g_ * u + h_ * v + 1.0;
  return {static_cast<float>((a_ * u + b_ * v + c_) / w),
          static_cast<float>((d_ * u + e_ * v + f_) / w)};
}

MarkerSamples sampleMarker(const cv::Mat& image, const Quad& quad, double border) {
  const SquareToQuad map(quad.corners);
  const double cell = (1.0 - 2.0 * border) / 6.0;
  const double spread = cell * 0.25;
  // Samples reach half a cell outside the marker (the white surround).
  const BilinearSampler sample(image, regionOf(map, -cell, 1.0 + cell));
  MarkerSamples out;

  // Black: the border band at 30 % and 70 % of its width (so a light margin or a border too thin
  // for the quad fails); white: half a cell outside the marker. Seven positions per side (one
  // corner, and opposite each code cell).
  constexpr int kRing = 28;
  cv::Point3d black[2 * kRing], white[kRing];
  float ring_samples[2 * kRing];  // the black border (middle depth) and the white surround
  int ring = 0;
  const double band = border * 0.5, outside = -cell * 0.5;
  for (int k = 0; k < 7; ++k) {
    const double t = k == 0 ? band : border + cell * (k - 0.5);
    for (int depth = 0; depth < 2; ++depth) {
      const double d = border * (depth == 0 ? 0.3 : 0.7);
      const double us[4] = {t, 1.0 - d, 1.0 - t, d}, vs[4] = {d, t, 1.0 - d, 1.0 - t};
      float b[4];
      sampleAreas(sample, map, us, vs, spread * 0.5, b);
      for (int s = 0; s < 4; ++s) black[2 * (4 * k + s) + depth] = {us[s], vs[s], b[s]};
    }
    const double us[4] = {t, 1.0 - outside, 1.0 - t, outside};
    const double vs[4] = {outside, t, 1.0 - outside, 1.0 - t};
    float w[4];
    samplesAt(sample, map, us, vs, w);
    for (int s = 0; s < 4; ++s) {
      ring_samples[ring] = 0.5f * static_cast<float>(black[2 * ring].z + black[2 * ring + 1].z);
      white[ring] = {us[s], vs[s], w[s]};
      ring_samples[kRing + ring] = static_cast<float>(white[ring].z);
      ++ring;
    }
  }
  const Plane black_level = fitPlane(black, 2 * kRing), white_level = fitPlane(white, kRing);
  out.contrast = static_cast<float>(white_level.at(0.5, 0.5) - black_level.at(0.5, 0.5));

  out.lowest = 255.0f;
  out.highest = 0.0f;
  // The cells four at a time, in row-major order.
  for (int first = 0; first < 36; first += 4) {
    double us[4], vs[4];
    gridCentres(first, 6, border, us, vs);
    float values[4];
    sampleAreas(sample, map, us, vs, spread, values);
    for (int i = 0; i < 4; ++i) {
      out.cells[first + i] = values[i];
      out.thresholds[first + i] =
          static_cast<float>(0.5 * (black_level.at(us[i], vs[i]) + white_level.at(us[i], vs[i])));
      out.lowest = std::min(out.lowest, values[i]);
      out.highest = std::max(out.highest, values[i]);
    }
  }
  for (const cv::Point3d& b : black) {
    const double threshold = 0.5 * (black_level.at(b.x, b.y) + white_level.at(b.x, b.y));
    out.border_light += b.z > threshold;
  }
  out.border_samples = 2 * kRing;
  // With as many dark as light samples, the median (the mean of the middle two) falls between
  // the lightest of the black and the darkest of the white.
  std::nth_element(ring_samples, ring_samples + kRing, ring_samples + 2 * kRing);
  const float upper = ring_samples[kRing];
  const float lower = *std::max_element(ring_samples, ring_samples + kRing);
  out.median = 0.5f * (lower + upper);
  return out;
}

bool hasFlatCodeArea(const cv::Mat& image, const std::array<cv::Point2f, 4>& corners,
                     double border) {
  const SquareToQuad map(corners);
  const double cell = (1.0 - 2.0 * border) / 6.0;
  const BilinearSampler sample(image, regionOf(map, -cell, 1.0 + cell));
  float lowest = 255.0f, highest = 0.0f;
  for (int first = 0; first < 36; first += 4) {  // the cells, row-major
    double us[4], vs[4];
    gridCentres(first, 6, border, us, vs);
    float values[4];
    samplesAt(sample, map, us, vs, values);
    for (const float value : values) {
      lowest = std::min(lowest, value);
      highest = std::max(highest, value);
    }
  }
  // The border's middle and half a cell outside, twice per side.
  float black = 0.0f, white = 0.0f;
  const double depth = 0.5 * border, outside = -0.5 * cell;
  for (const double t : {0.3, 0.7}) {
    float b[4], w[4];
    samplesAt(sample, map, {t, 1.0 - depth, 1.0 - t, depth}, {depth, t, 1.0 - depth, 1.0 - t}, b);
    samplesAt(sample, map, {t, 1.0 - outside, 1.0 - t, outside},
              {outside, t, 1.0 - outside, 1.0 - t}, w);
    black += b[0] + b[1] + b[2] + b[3];
    white += w[0] + w[1] + w[2] + w[3];
  }
  const float contrast = (white - black) / 8.0f;
  return contrast >= 16.0f && highest - lowest < 0.25f * contrast;
}

std::vector<float> sampleCodeArea(const cv::Mat& image, const Quad& quad, double border, int n) {
  const SquareToQuad map(quad.corners);
  const BilinearSampler sample(image, regionOf(map, 0.0, 1.0));
  const double cell = (1.0 - 2.0 * border) / n;
  std::vector<float> values(static_cast<size_t>(n) * n);
  for (int first = 0; first < n * n; first += 4) {
    double us[4], vs[4];
    gridCentres(first, n, border, us, vs);
    float four[4];
    sampleAreas(sample, map, us, vs, cell * 0.25, four);
    std::copy_n(four, std::min(4, n * n - first), values.begin() + first);
  }
  return values;
}

}  // namespace arbci::vision
