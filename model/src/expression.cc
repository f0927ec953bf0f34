#include "mbid/model/expression.h"

#include <muParser.h>

#include <cctype>
#include <cmath>
#include <stdexcept>

namespace mbid::model {
namespace {
constexpr size_t kMaxNameLength = 64;
}  // namespace

void ExpressionContext::Define(const std::string& name, double value) {
  // muparser refuses identifiers longer than 100 characters, with an exception of its own.
  const bool valid =
      !name.empty() && name.size() <= kMaxNameLength &&
      std::isalpha(static_cast<unsigned char>(name[0])) &&
      name.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_") ==
          std::string::npos;
  if (!valid) {
    throw std::invalid_argument("'" + name +
                                "' is not a parameter name (letters, digits, '_', starting with "
                                "a letter, at most 64 characters)");
  }
  if (name == "pi") throw std::invalid_argument("'pi' is reserved for the constant");
  values_[name] = value;
}

double ExpressionContext::Evaluate(const std::string& text) const {
  mu::Parser parser;
  std::map<std::string, double> copies = values_;
  double value = 0.0;
  try {
    // muparser names its constant _pi; the contract says pi. Variables are bound to copies the
    // parser reads at Eval(). Inside the try: muparser's errors are not std::exceptions.
    parser.DefineConst("pi", M_PI);
    for (auto& [name, copy] : copies) parser.DefineVar(name, &copy);
    parser.SetExpr(text);
    value = parser.Eval();
  } catch (const mu::Parser::exception_type& error) {
    const std::string token = error.GetToken();
    const mu::EErrorCodes code = error.GetCode();
    if ((code == mu::ecUNASSIGNABLE_TOKEN || code == mu::ecUNEXPECTED_VAR) && !token.empty() &&
        std::isalpha(static_cast<unsigned char>(token[0]))) {
      // YAML's true/false/yes/no: a value that is no number at all, not a parameter misspelt.
      static const char* const kBooleans[] = {"true",  "false", "True", "False", "TRUE",
                                              "FALSE", "yes",   "no",   "on",    "off"};
      for (const char* word : kBooleans) {
        if (text == word) throw std::invalid_argument("'" + text + "' is no number");
      }
      throw std::invalid_argument("unknown parameter '" + token + "' in '" + text + "'");
    }
    std::string why = error.GetMsg();  // muparser's sentence ends with a full stop
    while (!why.empty() && (why.back() == '.' || why.back() == ' ')) why.pop_back();
    throw std::invalid_argument("'" + text + "' does not parse: " + why);
  }
  if (!std::isfinite(value)) {
    throw std::invalid_argument("'" + text + "' is not finite (" + std::to_string(value) + ")");
  }
  return value;
}

}  // namespace mbid::model
