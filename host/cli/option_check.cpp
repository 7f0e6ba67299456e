#include "cli/option_check.h"

#include <cctype>

#include "core/error.h"

namespace pneumo::cli {

CLI::Validator checked_by(std::function<void(const std::string&)> parse, const std::string& name) {
  std::string upper = name;
  for (char& c : upper) c = char(std::toupper(static_cast<unsigned char>(c)));
  return CLI::Validator(
      [parse = std::move(parse)](std::string& value) -> std::string {
        try {
          parse(value);
          return "";
        } catch (const InputError& e) {
          return e.what();
        }
      },
      upper, name);
}

}  // namespace pneumo::cli
