#include "option_checks.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <string>

#include "commands.hpp"  // whole_number

namespace tessera::cli {
namespace {

/// The word as quoted in a message: at most 40 characters.
std::string shown(const std::string& word) {
  return "'" + (word.size() > 40 ? word.substr(0, 37) + "..." : word) + "'";
}

CLI::Validator range_check(bool strict, const char* name) {
  return CLI::Validator(
      [strict](std::string& word) -> std::string {
        double v;
        if (!whole_number(word, v)) return "expected a number, got " + shown(word);
        if (!std::isfinite(v) || (strict ? !(v > 0) : !(v >= 0)))
          return std::string("expected a finite number ") + (strict ? "> 0" : ">= 0") + ", got " + shown(word);
        return {};
      },
      name);
}

/// Digits after an optional sign ('+' or '-' for INT, '+' only for UINT).
/// The value must fit the widest type CLI11 converts to (64 bits); a
/// narrower target's overflow is CLI11's own conversion error.
std::string integer_syntax(const std::string& word, bool is_signed) {
  const std::string kind = is_signed ? "an integer" : "an integer >= 0";
  const bool sign = !word.empty() && (word[0] == '+' || (is_signed && word[0] == '-'));
  const std::size_t k = sign ? 1 : 0;
  bool digits = word.size() > k;
  for (std::size_t i = k; i < word.size(); ++i) digits &= word[i] >= '0' && word[i] <= '9';
  if (!digits) return "expected " + kind + ", got " + shown(word);
  errno = 0;
  if (is_signed)
    (void)std::strtoll(word.c_str(), nullptr, 10);
  else
    (void)std::strtoull(word.c_str(), nullptr, 10);
  if (errno == ERANGE) return "expected " + kind + " of at most 64 bits, got " + shown(word);
  return {};
}

CLI::Validator syntax_check(const std::string& type) {
  // No description: the option's type name in --help stays as it was.
  if (type == "FLOAT")
    return CLI::Validator(
        [](std::string& word) -> std::string {
          double v;
          return whole_number(word, v) ? std::string() : "expected a number, got " + shown(word);
        },
        "");
  const bool is_signed = type == "INT";
  return CLI::Validator([is_signed](std::string& word) { return integer_syntax(word, is_signed); }, "");
}

}  // namespace

const CLI::Validator NonNegative = range_check(false, "NONNEGATIVE");
const CLI::Validator Positive = range_check(true, "POSITIVE");

void require_number_syntax(CLI::App& app) {
  for (CLI::Option* opt : app.get_options()) {
    const std::string full = opt->get_type_name();
    const std::string type = full.substr(0, full.find_first_of(":="));
    if (type == "INT" || type == "UINT" || type == "FLOAT") opt->check(syntax_check(type));
  }
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) require_number_syntax(*sub);
}

}  // namespace tessera::cli
