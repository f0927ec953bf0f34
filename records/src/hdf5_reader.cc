// mbid's HDF5 measurement file as a RawTable: the start time and interval pass through exactly
// (bit-exact round trips), and the stated units are converted like any others.
#include <fmt/format.h>

#include "mbid/common/hdf5_io.h"
#include "readers.h"

namespace mbid::records::internal {

RawTable ReadHdf5(const std::string& path) {
  const Measurement m = ReadMeasurementH5(path);
  RawTable table;
  table.format = "hdf5";
  table.source = m.source;
  table.start = m.start_time_s;
  table.interval = m.sample_interval_s;
  table.time_unit = "s";
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
