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
    // Every file the conversion writes: a .mhd's data file beside it is overwritten as surely as the header.
    const WriteOptions options;
    for (const std::string& file : files_written_by(*out, options)) {
      std::error_code ec;   // symlink_status: a link under the name, even a dangling one, is there too
      const bool there = std::filesystem::symlink_status(file, ec).type() != std::filesystem::file_type::not_found;
      if (there && !*force)
        throw InputError(file + ": already exists" + (file == *out ? "" : " (the data file " + *out + " names)") +
                         "; use --force to overwrite");
      check_writable_target(file);
    }
    const Volume v = read_volume(*in);
    write_volume(v, *out, options);
    log::info("wrote " + *out);
    return 0;
  };
}

}  // namespace pneumo::cli
