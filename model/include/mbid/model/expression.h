#pragma once

#include <map>
#include <string>

namespace mbid::model {

// Named numbers of a machine description (`model.parameters`) and the arithmetic on them that
// numeric fields may use: + - * / ^, parentheses, sin cos tan sqrt abs, pi (muparser).
class ExpressionContext {
 public:
  // Adds or replaces a named value. Names are letters, digits and '_', starting with a letter.
  void Define(const std::string& name, double value);
  bool Has(const std::string& name) const { return values_.count(name) > 0; }
  const std::map<std::string, double>& values() const { return values_; }

  // The value of `text`. Throws std::invalid_argument whose what() says what is wrong in the
  // user's terms ("unknown parameter 'boom_lenght_m' in 'boom_lenght_m / 2'", "does not parse:
  // ..."), or that the value is not finite.
  double Evaluate(const std::string& text) const;

 private:
  std::map<std::string, double> values_;
};

}  // namespace mbid::model
