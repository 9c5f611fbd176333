// `arbci marker make`: printable markers (PNG at print resolution and SVG), singly or on a
// labelled sheet. `arbci marker train`: a template pattern (.patt) from an image of a marker.
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>

#include <opencv2/imgcodecs.hpp>

#include "arbci/vision/id_codes.h"
#include "arbci/vision/marker_detector.h"
#include "arbci/vision/marker_printer.h"
#include "arbci/vision/settings.h"
#include "commands/commands.h"
#include "support/cli_error.h"
#include "support/id_list.h"
#include "support/name_list.h"
#include "support/output_path.h"
#include "support/png.h"
#include "support/schema_option.h"

namespace arbci::app {
namespace {

struct MakeOptions {
  std::string kind;  // tracker.kind
  std::string ids;
  double border = 0.0;  // 0: the kind's own (bch 0.125, simple 0.25)
  double size_mm = 80.0;
  int dpi = 300;
  bool sheet = false;
  std::string out;
};

void writeText(const std::filesystem::path& path, const std::string& text) {
  std::ofstream file(path);
  file << text;
  file.close();
  if (!file) throw CliError("cannot write " + path.string());
}

void makeMarkers(const MakeOptions& options) {
  const auto& family = vision::markerFamilies().at(options.kind);
  const vision::IdCode* code = family.make.code;
  if (!code) throw CliError("--kind " + options.kind + " is not printable here");
  const vision::MarkerKind kind{family.name};
  // The kind's own border unless given: what detect --kind expects of it.
  const double border = options.border > 0.0 ? options.border : family.make.border;
  const std::vector<int> ids = parseIdList(options.ids, code->max_id);
  vision::PrintLayout layout;
  layout.size_mm = options.size_mm;
  layout.dpi = options.dpi;
  std::filesystem::path base(options.out);
  if (base.extension() == ".png" || base.extension() == ".svg") base.replace_extension();
  for (int id : ids) {
    const int margin = code->rotation_margin ? code->rotation_margin(id) : 5;
    if (margin < 5) {
      std::cerr << "arbci: warning: " << options.kind << " id " << id
                << " turned by 90/180/270 degrees lies within " << margin
                << " bits of another id; prefer another id\n";
    }
  }
  auto write = [&](const std::filesystem::path& stem, const cv::Mat& image,
                   const std::string& svg) {
    std::filesystem::path png = stem, vector = stem;
    png += ".png";
    vector += ".svg";
    ensureWritable(png);
    writePng(png, image, options.dpi);
    writeText(vector, svg);
    std::cout << png.string() << "\n" << vector.string() << "\n";
  };
  try {
    if (options.sheet) {
      write(base, vision::renderSheetImage(kind, ids, border, layout),
            vision::renderSheetSvg(kind, ids, border, layout));
    } else {
      for (int id : ids) {
        std::filesystem::path stem = base;
        if (ids.size() > 1) stem += "-" + std::to_string(id);
        write(stem, vision::renderMarkerImage(kind, id, border, layout),
              vision::renderMarkerSvg(kind, id, border, layout));
      }
    }
  } catch (const std::invalid_argument& error) {
    throw CliError(error.what());
  }
}

struct PatternTrainOptions {
  std::string image;
  int id = 0;
  double border = 0.0;  // 0: the square's border as printed, 0.25 or 0.125 (marker make's)
  std::string out;
};

// The largest square in a face-on image of the marker, sampled as a template pattern.
void trainPattern(const PatternTrainOptions& options) {
  const cv::Mat image = cv::imread(options.image, cv::IMREAD_GRAYSCALE);
  if (image.empty()) throw CliError("cannot read image " + options.image);
  ensureWritable(options.out);
  // Not given: the standard borders in turn, the wide one (ARToolKit's patterns) first, then
  // marker make's thin BCH border, so a marker made with marker make's defaults trains as it is.
  const std::vector<double> borders =
      options.border > 0.0 ? std::vector<double>{options.border} : std::vector<double>{0.25, 0.125};
  std::optional<vision::TemplatePattern> pattern;
  double used = 0.0;
  for (double border : borders) {
    if ((pattern = vision::trainTemplate(image, options.id, border))) {
      used = border;
      break;
    }
  }
  if (!pattern) {
    throw CliError("no black-bordered square found in " + options.image + " (border " +
                   (borders.size() == 1 ? std::to_string(borders[0]) : "0.25 or 0.125") +
                   " of the side; --border for another)");
  }
  pattern->save(options.out);
  if (options.border <= 0.0) {
    std::cerr << "trained with a border of " << used << " of the side (detect --kind template"
              << " --border " << used << ")\n";
  }
  if (pattern->rotationalSymmetry() > 0.9f) {
    std::cerr << "arbci: warning: the pattern looks alike when turned; its orientation will be "
                 "ambiguous\n";
  }
  std::cout << options.out << "\n";
}

}  // namespace

void addMarkerCommand(CLI::App& root, int& exit_code) {
  auto* marker = root.add_subcommand("marker", "Printable markers and template patterns");
  marker->require_subcommand(1);

  auto make = std::make_shared<MakeOptions>();
  auto* make_command = marker->add_subcommand(
      "make", "Write printable markers as PNG (at print resolution) and SVG");
  std::vector<std::string> printable;
  for (const auto& family : vision::markerFamilies().entries())
    if (family.make.printable()) printable.push_back(family.name);
  schemaOption(*make_command, "--kind", make->kind, vision::detectorSchema().at("kind"),
               "printable: " + joinNames(printable) + " (bch ids 0..4095, simple 0..511)")
      ->check(CLI::IsMember(printable));
  make_command->add_option("--id", make->ids, "Marker id, list or range: 7, 1,4,9 or 0-11")
      ->required();
  schemaOptionOwnDefault(*make_command, "--border", make->border,
                         vision::detectorSchema().at("border"), 0.0,
                         "the kind's own, bch 0.125, simple 0.25, as detect --kind expects")
      ->check(CLI::IsMember({0.125, 0.25}));
  make_command->add_option("--size-mm", make->size_mm, "Side of the black square in millimetres")
      ->check(CLI::Range(1.0, 1000.0))
      ->capture_default_str();
  make_command->add_option("--dpi", make->dpi, "PNG resolution")
      ->check(CLI::Range(72, 2400))
      ->capture_default_str();
  make_command->add_flag("--sheet", make->sheet, "All ids on one labelled A4 sheet");
  make_command->add_option("--out", make->out, "Output file name (.png and .svg are written)")
      ->required();
  make_command->callback([make, &exit_code] {
    makeMarkers(*make);
    exit_code = 0;
  });

  auto train = std::make_shared<PatternTrainOptions>();
  auto* train_command = marker->add_subcommand(
      "train", "Train a template pattern (ARToolKit .patt) from a face-on image of a marker");
  train_command->add_option("--image", train->image, "Image of the marker, seen face-on")
      ->required();
  train_command->add_option("--id", train->id, "Id to give the pattern")->capture_default_str();
  schemaOptionOwnDefault(*train_command, "--border", train->border,
                         vision::detectorSchema().at("border"), 0.0,
                         "0.25, else 0.125, marker make's for bch; the one used is printed");
  train_command->add_option("--out", train->out, "Pattern file to write")->required();
  train_command->callback([train, &exit_code] {
    trainPattern(*train);
    exit_code = 0;
  });
}

}  // namespace arbci::app
