#include "arbci/vision/marker_printer.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "arbci/vision/id_codes.h"
#include "arbci/vision/marker_family.h"

namespace arbci::vision {
namespace {

constexpr double kA4Width = 210.0, kA4Height = 297.0, kPageMargin = 10.0, kLabelHeight = 8.0;

int cellsPerSide(double border) {
  if (std::abs(border - 0.125) < 1e-9) return 8;
  if (std::abs(border - 0.25) < 1e-9) return 12;
  throw std::invalid_argument(
      "printable markers have border 0.125 (thin) or 0.25 (standard), got " +
      std::to_string(border));
}

struct Geometry {
  int cells;        // black square, in cells
  double cell_mm;   // cell size
  double quiet_mm;  // white margin
  double outer_mm() const { return cells * cell_mm + 2.0 * quiet_mm; }
};

Geometry geometryOf(double border, const PrintLayout& layout) {
  if (!(layout.size_mm > 0.0) || layout.size_mm > 1000.0) {
    throw std::invalid_argument("marker size must be in (0, 1000] mm, got " +
                                std::to_string(layout.size_mm));
  }
  if (layout.dpi < 72 || layout.dpi > 2400) {
    throw std::invalid_argument("dpi must be 72..2400, got " + std::to_string(layout.dpi));
  }
  Geometry g;
  g.cells = cellsPerSide(border);
  g.cell_mm = layout.size_mm / g.cells;
  g.quiet_mm = std::max(g.cell_mm, layout.min_quiet_zone_mm);
  return g;
}

int pixels(double mm, int dpi) {
  return static_cast<int>(std::lround(mm / 25.4 * dpi));
}

// Draws `cells` (0 black) with its top-left black-square corner at (x_mm, y_mm).
void drawCells(cv::Mat& image, const cv::Mat& cells, double x_mm, double y_mm, double cell_mm,
               int dpi) {
  for (int r = 0; r < cells.rows; ++r) {
    for (int c = 0; c < cells.cols; ++c) {
      if (cells.at<std::uint8_t>(r, c) != 0) continue;
      const cv::Point a(pixels(x_mm + c * cell_mm, dpi), pixels(y_mm + r * cell_mm, dpi));
      const cv::Point b(pixels(x_mm + (c + 1) * cell_mm, dpi),
                        pixels(y_mm + (r + 1) * cell_mm, dpi));
      cv::rectangle(image, cv::Rect(a, b), cv::Scalar(0), cv::FILLED);
    }
  }
}

void svgCells(std::ostringstream& svg, const cv::Mat& cells, double x_mm, double y_mm,
              double cell_mm) {
  svg << "<path fill=\"#000\" d=\"";
  for (int r = 0; r < cells.rows; ++r) {
    for (int c = 0; c < cells.cols; ++c) {
      if (cells.at<std::uint8_t>(r, c) != 0) continue;
      svg << "M" << x_mm + c * cell_mm << " " << y_mm + r * cell_mm << "h" << cell_mm << "v"
          << cell_mm << "h" << -cell_mm << "z";
    }
  }
  svg << "\"/>\n";
}

std::string label(MarkerKind kind, int id, const PrintLayout& layout) {
  std::ostringstream text;
  text << toString(kind) << " " << id << "  (" << layout.size_mm << " mm)";
  return text.str();
}

struct SheetSlot {
  int id;
  double x_mm, y_mm;  // top-left of the quiet zone
};

std::vector<SheetSlot> layoutSheet(const std::vector<int>& ids, const Geometry& g,
                                   double& height_mm) {
  const double cell_w = g.outer_mm(), cell_h = g.outer_mm() + kLabelHeight;
  const int columns = static_cast<int>((kA4Width - 2 * kPageMargin) / cell_w);
  if (columns < 1 || cell_h > kA4Height - 2 * kPageMargin) {
    throw std::invalid_argument("a marker of this size does not fit on an A4 sheet with its label");
  }
  std::vector<SheetSlot> slots;
  for (size_t i = 0; i < ids.size(); ++i) {
    const int row = static_cast<int>(i) / columns, column = static_cast<int>(i) % columns;
    slots.push_back({ids[i], kPageMargin + column * cell_w, kPageMargin + row * cell_h});
  }
  const int rows = (static_cast<int>(ids.size()) + columns - 1) / columns;
  height_mm = std::max(kA4Height, 2 * kPageMargin + rows * cell_h);
  return slots;
}

}  // namespace

cv::Mat markerCells(MarkerKind kind, int id, double border) {
  const int cells = cellsPerSide(border);
  const int offset = (cells - 6) / 2;
  const IdCode* code = familyOf(kind).code;
  if (!code) {
    std::string printable;
    for (const auto& family : markerFamilies().entries())
      if (family.make.printable()) printable += (printable.empty() ? "" : ", ") + family.name;
    throw std::invalid_argument("only " + printable + " markers can be drawn, not " +
                                toString(kind));
  }
  if (id < 0 || id > code->max_id)
    throw std::invalid_argument(toString(kind) + " ids are 0.." + std::to_string(code->max_id) +
                                ", got " + std::to_string(id));
  const CodeGrid grid = wordToGrid(code->encode(id));
  cv::Mat image(cells, cells, CV_8UC1, cv::Scalar(0));
  for (int r = 0; r < 6; ++r) {
    for (int c = 0; c < 6; ++c)
      image.at<std::uint8_t>(r + offset, c + offset) = grid[r * 6 + c] ? 255 : 0;
  }
  return image;
}

cv::Mat renderMarkerImage(MarkerKind kind, int id, double border, const PrintLayout& layout) {
  const Geometry g = geometryOf(border, layout);
  const cv::Mat cells = markerCells(kind, id, border);
  const int side = pixels(g.outer_mm(), layout.dpi);
  cv::Mat image(side, side, CV_8UC1, cv::Scalar(255));
  drawCells(image, cells, g.quiet_mm, g.quiet_mm, g.cell_mm, layout.dpi);
  return image;
}

std::string renderMarkerSvg(MarkerKind kind, int id, double border, const PrintLayout& layout) {
  const Geometry g = geometryOf(border, layout);
  const cv::Mat cells = markerCells(kind, id, border);
  std::ostringstream svg;
  const double side = g.outer_mm();
  svg << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
      << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << side << "mm\" height=\"" << side
      << "mm\" viewBox=\"0 0 " << side << " " << side << "\">\n"
      << "<title>" << label(kind, id, layout) << "</title>\n"
      << "<rect width=\"" << side << "\" height=\"" << side << "\" fill=\"#fff\"/>\n";
  svgCells(svg, cells, g.quiet_mm, g.quiet_mm, g.cell_mm);
  svg << "</svg>\n";
  return svg.str();
}

cv::Mat renderSheetImage(MarkerKind kind, const std::vector<int>& ids, double border,
                         const PrintLayout& layout) {
  const Geometry g = geometryOf(border, layout);
  double height_mm = 0.0;
  const std::vector<SheetSlot> slots = layoutSheet(ids, g, height_mm);
  cv::Mat image(pixels(height_mm, layout.dpi), pixels(kA4Width, layout.dpi), CV_8UC1,
                cv::Scalar(255));
  for (const SheetSlot& slot : slots) {
    const cv::Mat cells = markerCells(kind, slot.id, border);
    drawCells(image, cells, slot.x_mm + g.quiet_mm, slot.y_mm + g.quiet_mm, g.cell_mm, layout.dpi);
    cv::rectangle(image,
                  cv::Rect(cv::Point(pixels(slot.x_mm, layout.dpi), pixels(slot.y_mm, layout.dpi)),
                           cv::Point(pixels(slot.x_mm + g.outer_mm(), layout.dpi),
                                     pixels(slot.y_mm + g.outer_mm(), layout.dpi))),
                  cv::Scalar(190), 1);
    const double text_scale = layout.dpi / 300.0;
    cv::putText(image, label(kind, slot.id, layout),
                cv::Point(pixels(slot.x_mm + 1.0, layout.dpi),
                          pixels(slot.y_mm + g.outer_mm() + 5.0, layout.dpi)),
                cv::FONT_HERSHEY_SIMPLEX, 1.2 * text_scale, cv::Scalar(0),
                std::max(1, static_cast<int>(2 * text_scale)), cv::LINE_AA);
  }
  return image;
}

std::string renderSheetSvg(MarkerKind kind, const std::vector<int>& ids, double border,
                           const PrintLayout& layout) {
  const Geometry g = geometryOf(border, layout);
  double height_mm = 0.0;
  const std::vector<SheetSlot> slots = layoutSheet(ids, g, height_mm);
  std::ostringstream svg;
  svg << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
      << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << kA4Width << "mm\" height=\""
      << height_mm << "mm\" viewBox=\"0 0 " << kA4Width << " " << height_mm << "\">\n"
      << "<rect width=\"" << kA4Width << "\" height=\"" << height_mm << "\" fill=\"#fff\"/>\n";
  for (const SheetSlot& slot : slots) {
    const cv::Mat cells = markerCells(kind, slot.id, border);
    svg << "<rect x=\"" << slot.x_mm << "\" y=\"" << slot.y_mm << "\" width=\"" << g.outer_mm()
        << "\" height=\"" << g.outer_mm()
        << "\" fill=\"none\" stroke=\"#bbb\" stroke-width=\"0.2\"/>\n";
    svgCells(svg, cells, slot.x_mm + g.quiet_mm, slot.y_mm + g.quiet_mm, g.cell_mm);
    svg << "<text x=\"" << slot.x_mm + 1.0 << "\" y=\"" << slot.y_mm + g.outer_mm() + 5.0
        << "\" font-family=\"sans-serif\" font-size=\"4\">" << label(kind, slot.id, layout)
        << "</text>\n";
  }
  svg << "</svg>\n";
  return svg.str();
}

}  // namespace arbci::vision
