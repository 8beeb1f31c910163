// `pt merge PARTS... -o OUT`: the parts of a split render (pt render --part K/N) into one image,
// written atomically as EXR (mean and variance) or PNG. Refuses, naming the file and writing
// nothing, parts of different renders, a missing or duplicated part, and files that are not parts.
#include <filesystem>

#include "core/image/image.h"
#include "core/image/tonemap.h"
#include "core/util/error.h"
#include "renderer/commands/cli_options.h"
#include "renderer/commands/commands.h"
#include "renderer/farm/merge.h"
#include "renderer/render/output_format.h"

namespace pt {
namespace fs = std::filesystem;
namespace {

struct MergeArgs {
  std::vector<std::string> parts;
  std::string output;
  std::optional<float> exposure;
  std::string tonemap = "clip";
  bool quiet = false;
};

int run_merge(const MergeArgs& args) {
  const OutputFormat format = output_format(args.output);
  const Tonemap tonemap = kTonemapNames.parse(args.tonemap);
  for (const std::string& part : args.parts) {
    std::error_code ec;
    if (fs::equivalent(part, args.output, ec)) throw Error(args.output, "is one of the parts; merge into another file");
  }
  MergedParts merged = merge_parts(args.parts);
  size_t clamped = 0;
  Image image = merged.film.to_image(format == OutputFormat::kExr, &clamped);
  if (clamped > 0) {
    std::fprintf(stderr, "pt: warning: %zu pixel values (mean or variance) exceeded the float range and were clamped to 3.4e38\n",
                 clamped);
  }
  image.metadata = merged.metadata;
  if (is_display_referred(format)) {
    apply_tonemap(image, tonemap, args.exposure.value_or(0.0f));
  } else if (args.exposure || args.tonemap != "clip") {
    std::fprintf(stderr, "pt: warning: --exposure and --tonemap have no effect on %s, which holds linear radiance\n",
                 args.output.c_str());
  }
  write_image(args.output, image);

  for (const std::string& line : merged.short_parts) {
    std::fprintf(stderr, "pt: warning: %s (interrupted or time-limited; pt render ... --resume continues it)\n", line.c_str());
  }
  uint32_t lo = merged.film.min_count(), hi = merged.film.max_count();
  if (!merged.short_parts.empty()) {
    std::fprintf(stderr, "pt: merged %d parts (%zu short) into %s: %u%s of %d samples per pixel\n", merged.parts,
                 merged.short_parts.size(), args.output.c_str(), lo, hi != lo ? (" to " + std::to_string(hi)).c_str() : "",
                 merged.frame_spp);
  } else if (!args.quiet) {
    std::fprintf(stderr, "pt: merged %d parts (split by %s) into %s: %u spp\n", merged.parts, kSplitNames.name(merged.split),
                 args.output.c_str(), lo);
  }
  return 0;
}

}  // namespace

void add_merge_command(CLI::App& app, Action& action) {
  auto args = std::make_shared<MergeArgs>();
  CLI::App* cmd = app.add_subcommand("merge", "Merge the parts of a split render (pt render --part K/N) into one image");
  cmd->add_option("parts", args->parts, "Every part file of the frame, in any order")->required();
  cmd->add_option("-o,--output", args->output, "Output image: .exr (linear float + variance), .hdr, .png or .jpg (8-bit sRGB)")->required();
  cmd->add_option("--exposure", args->exposure, "Exposure in stops for 8-bit outputs (.png, .jpg)")->check(finite_number(-40.0, 40.0));
  cmd->add_option("--tonemap", args->tonemap, "Tone curve for 8-bit outputs: clip (default), aces or filmic")
      ->check(CLI::IsMember(kTonemapNames.names()));
  cmd->add_flag("-q,--quiet", args->quiet, "No summary on stderr (warnings about short parts still appear)");
  cmd->callback([&action, args] { action = [args] { return run_merge(*args); }; });
}

}  // namespace pt
