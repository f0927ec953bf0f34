#include "mbid/app/gnuplot.h"

#include <fmt/format.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "mbid/common/atomic_file.h"

namespace mbid::app {
namespace {

std::string Quote(const std::string& text) {
  std::string quoted = "\"";
  for (char c : text) {
    if (c == '"' || c == '\\') quoted += '\\';
    quoted += c;
  }
  return quoted + "\"";
}

}  // namespace

bool GnuplotAvailable() {
  return std::system("gnuplot -e 'set terminal pngcairo' > /dev/null 2>&1") == 0;
}

void DrawFigure(const Figure& figure, const std::string& png_path) {
  AtomicFile png(png_path);
  const std::string data_path = png.temp_path() + ".dat";
  const std::string script_path = png.temp_path() + ".gp";
  const std::string log_path = png.temp_path() + ".log";
  {
    // One data block per series, separated by two blank lines (gnuplot's "index").
    std::ofstream data(data_path);
    for (const PlotSeries& series : figure.series) {
      for (Eigen::Index i = 0; i < series.x.size(); ++i) {
        data << fmt::format("{:.10g} {:.10g}\n", series.x[i], series.y[i]);
      }
      data << "\n\n";
    }
  }
  {
    std::ofstream script(script_path);
    script << fmt::format("set terminal pngcairo size {},{} font 'Sans,10' noenhanced\n",
                          figure.width_px, figure.height_px);
    script << "set output " << Quote(png.temp_path()) << "\n";
    script << "set title " << Quote(figure.title) << "\n";
    script << "set xlabel " << Quote(figure.x_label) << "\n";
    script << "set ylabel " << Quote(figure.y_label) << "\n";
    script << "set grid\nset key " << figure.key << "\nset offsets 0, 0, graph 0.05, graph 0.05\n";
    if (figure.log_y) script << "set logscale y\nset format y '%.0e'\n";
    if (figure.log_x) script << "set logscale x\nset format x '%g'\n";
    if (!figure.x_range.empty()) script << "set xrange " << figure.x_range << "\n";
    if (!figure.y_range.empty()) script << "set yrange " << figure.y_range << "\n";
    if (figure.pad_x) script << "set offsets graph 0.03, graph 0.03, graph 0.05, graph 0.05\n";
    script << "plot ";
    for (size_t k = 0; k < figure.series.size(); ++k) {
      if (k > 0) script << ", \\\n     ";
      script << Quote(data_path) << " index " << k << " using 1:2 with " << figure.series[k].style
             << " title " << Quote(figure.series[k].title);
    }
    script << "\n";
  }
  const std::string command = "gnuplot " + script_path + " > " + log_path + " 2>&1";
  const int status = std::system(command.c_str());
  std::string complaint;
  if (status != 0) {
    std::ifstream log(log_path);
    std::stringstream text;
    text << log.rdbuf();
    complaint = text.str();
  }
  std::filesystem::remove(data_path);
  std::filesystem::remove(script_path);
  std::filesystem::remove(log_path);
  if (status != 0) {
    throw std::runtime_error("gnuplot failed on " + png_path + ": " + complaint);
  }
  png.Commit();
}

}  // namespace mbid::app
