#pragma once
// `pneumo bogus` names the word it did not understand, the subcommands there are, and the closest
// one when the word looks like a typo; CLI11 alone says only that an argument was not expected.
#include <string>
#include <vector>

namespace pneumo::cli {

/// The first word of `args` (argv without the program) that is neither an option nor the value of
/// one of `value_options` (global options that take a value, e.g. "--threads"): if it names none
/// of `subcommands`, the one-line message for it; "" otherwise (CLI11 then reports the rest).
std::string unknown_subcommand_message(const std::vector<std::string>& args,
                                       const std::vector<std::string>& value_options,
                                       const std::vector<std::string>& subcommands);

}  // namespace pneumo::cli
