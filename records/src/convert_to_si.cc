#include "mbid/records/records.h"
#include "units.h"

namespace mbid::records {

std::vector<std::string> ConvertToSi(Measurement* measurement, const std::string& source) {
  std::vector<std::string> conversions;
  for (size_t c = 0; c < measurement->units.size(); ++c) {
    const std::string field = "units/" + measurement->channels[c];
    const std::string& unit = measurement->units[c];
    const std::string target = internal::SiUnitFor(unit, source, field);
    const internal::UnitConversion conversion =
        internal::FindConversion(unit, target, source, field);
    if (!conversion.identity()) {
      auto column = measurement->values.col(static_cast<Eigen::Index>(c));
      column = (column.array() * conversion.scale + conversion.offset).matrix();
      conversions.push_back(
          internal::DescribeConversion(measurement->channels[c], unit, target, conversion));
    }
    measurement->units[c] = target;
  }
  return conversions;
}

}  // namespace mbid::records
