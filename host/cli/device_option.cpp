#include "cli/device_option.h"

#include "cli/option_check.h"
#include "scene/scene.h"

namespace pneumo::cli {

CLI::Option* add_device_option(CLI::App* cmd, std::string& device, const std::string& role) {
  return cmd->add_option("--device", device, role + ". " + scene_key_help("device"))
      ->check(checked_by([](const std::string& value) { (void)parse_scene(nlohmann::json{{"device", value}}, ""); },
                         "device"));
}

}  // namespace pneumo::cli
