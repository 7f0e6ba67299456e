#include "cli/device_option.h"

#include "core/error.h"
#include "scene/scene.h"

namespace pneumo::cli {

CLI::Option* add_device_option(CLI::App* cmd, std::string& device, const std::string& role) {
  return cmd->add_option("--device", device, role + ". " + scene_key_help("device"))
      ->check(CLI::Validator(
          [](std::string& value) -> std::string {
            try {
              (void)parse_scene(nlohmann::json{{"device", value}}, "");
              return "";
            } catch (const InputError& e) {
              return e.what();
            }
          },
          "DEVICE", "device"));
}

}  // namespace pneumo::cli
