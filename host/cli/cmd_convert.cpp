#include <filesystem>

#include "cli/commands.h"
#include "core/error.h"
#include "core/log.h"
#include "core/atomic_file.h"
#include "io/volume_io.h"

namespace pneumo::cli {

Run add_convert(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "convert", "Rewrite a volume in another format (a DICOM series to NIfTI or NRRD, NIfTI to NRRD for 3D Slicer, ...)");
  auto in = std::make_shared<std::string>();
  auto out = std::make_shared<std::string>();
  auto force = std::make_shared<bool>(false);
  cmd->add_option("input", *in, "A .nii, .nii.gz, .mha, .mhd, .nrrd or .nhdr volume, or the folder of a DICOM CT series")
      ->required();
  cmd->add_option("output", *out, "The file to write; its name chooses the format (.nii, .nii.gz, .mha, .mhd, .nrrd)")
      ->required();
  cmd->add_flag("--force", *force, "Overwrite OUTPUT if it exists");
  return [=] {
    volume_format_from_path(*out);   // an unknown name is refused before the input is read
    if (std::filesystem::exists(*out) && !*force) throw InputError(*out + ": already exists; use --force to overwrite");
    check_writable_target(*out);
    const Volume v = read_volume(*in);
    write_volume(v, *out);
    log::info("wrote " + *out);
    return 0;
  };
}

}  // namespace pneumo::cli
