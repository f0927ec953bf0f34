// mbid's HDF5 measurement file as a RawTable: the start time and interval pass through exactly
// (bit-exact round trips), and the stated units are converted like any others.
#include <fmt/format.h>

#include "mbid/common/error.h"
#include "mbid/common/hdf5_io.h"
#include "readers.h"
#include "units.h"

namespace mbid::records::internal {

RawTable ReadHdf5(const std::string& path, const std::string& time_unit) {
  // The time dataset's unit (or the user's, over it) is applied before its step is checked
  // against sample_interval_s; the table carries the grid back in that unit, so that the
  // import's time base states the conversion as for any other format.
  double scale = 1;
  std::string unit = "s";
  const Measurement m = ReadMeasurementH5(
      path, [&](const std::string& stated, const std::string& field, std::string* read_in) {
        unit = time_unit.empty() ? stated : time_unit;
        if (unit.empty()) {
          throw InputError(path, field, "missing",
                           "the time's unit ('s', 'ms'), or --time-unit (record key time_unit)");
        }
        *read_in = unit;
        scale = unit == "s" ? 1.0 : FindConversion(unit, "s", path, field).scale;
        return scale;
      });
  RawTable table;
  table.format = "hdf5";
  table.source = m.source;
  table.start = m.start_time_s / scale;
  table.interval = m.sample_interval_s / scale;
  table.time_unit = unit;
  table.time_where = "/measurement/time";
  table.si_by_contract = true;
  for (int c = 0; c < m.channel_count(); ++c) {
    RawColumn column;
    column.name = m.channels[static_cast<size_t>(c)];
    column.unit = m.units[static_cast<size_t>(c)];
    column.where = "/measurement/" + column.name;
    column.values.assign(m.values.col(c).data(), m.values.col(c).data() + m.samples());
    table.columns.push_back(std::move(column));
  }
  return table;
}

}  // namespace mbid::records::internal
