#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>

#include "cli/commands.h"
#include "io/volume_info.h"
#include "io/volume_io.h"

namespace pneumo::cli {

Run add_info(CLI::App& app) {
  auto* cmd = app.add_subcommand("info", "Describe a volume: grid, world geometry, voxel type, values, labels");
  auto path = std::make_shared<std::string>();
  auto json = std::make_shared<bool>(false);
  cmd->add_option("file", *path, "A .nii, .nii.gz, .mha, .mhd, .nrrd or .nhdr volume, or the folder of a DICOM CT series")->required();
  cmd->add_flag("--json", *json, "Print JSON (keys dims, spacing_mm, origin_mm, direction, orientation, ...)");
  return [=] {
    const Volume v = read_volume(*path);
    const VolumeInfo info = describe_volume(v);
    if (*json) std::cout << volume_info_json(info, *path).dump(2) << "\n";
    else std::cout << volume_info_text(info, *path);
    return 0;
  };
}

}  // namespace pneumo::cli
