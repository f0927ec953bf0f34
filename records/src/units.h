#pragma once

// Units through udunits2 (docs/records.md): the unit texts files and users write, converted to
// the SI units mbid computes in. Every unit goes through the library; none is guessed.

#include <string>
#include <vector>

namespace mbid::records::internal {

// y_SI = scale * y + offset.
struct UnitConversion {
  double scale = 1.0;
  double offset = 0.0;
  bool identity() const { return scale == 1.0 && offset == 0.0; }
};

// Whether udunits2 reads `text` as a unit (with mbid's aliases: deg, gn/g0/g_n).
bool IsUnit(const std::string& text);

// The SI unit of the dimension of `unit`: angles go to "rad", angular rates to "rad/s", lengths
// to "m", accelerations to "m/s^2", ... (udunits treats the radian as dimensionless, so angles
// are told apart by the radian in the unit's definition). An unknown unit is an InputError
// naming `source` and `field`.
std::string SiUnitFor(const std::string& unit, const std::string& source, const std::string& field);

// SI units that are their own SiUnitFor, answered without udunits2: reading its unit database
// costs 25 M instructions, 8% of `mbid identify` on a small file already in SI.
const std::vector<std::string>& SelfSiUnits();
// SiUnitFor through udunits2 always (the check of SelfSiUnits).
std::string SiUnitByUdunits(const std::string& unit, const std::string& source,
                            const std::string& field);

// The conversion from `from` to `to`. An unknown unit, or units of different dimensions
// (counting the radian as one: deg to 1 is refused), is an InputError naming `source` and
// `field`, the unit text and the unit expected; for a sensor's raw signal (V, mV, mA) the advice
// shows its calibration as a scaled unit for `column`.
UnitConversion FindConversion(const std::string& from, const std::string& to,
                              const std::string& source, const std::string& field,
                              const std::string& column = "COLUMN");

// The unit a sensor of `si_unit`'s kind is commonly logged in, for examples in messages: "deg"
// for rad, "mm" for m, "gn" for m/s^2, "deg/s" for rad/s, "mm/s" for m/s, else `si_unit` ("deg"
// for none).
std::string EverydayUnit(const std::string& si_unit);

// Applies `conversion` in place (NaN gap markers stay NaN).
void Convert(const UnitConversion& conversion, std::vector<double>* values);

// The import report's line for a channel's conversion: "theta: deg -> rad (x 0.0174533)", with
// "+ offset" where there is one.
std::string DescribeConversion(const std::string& channel, const std::string& from,
                               const std::string& to, const UnitConversion& conversion);

}  // namespace mbid::records::internal
