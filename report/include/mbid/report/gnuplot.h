#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace mbid::report {

namespace internal {
struct FigureDrawing;
}

// One curve or point set of a figure.
struct PlotSeries {
  std::string title;
  Eigen::VectorXd x;
  Eigen::VectorXd y;
  std::string style = "lines";  // gnuplot "with" clause: "lines", "points pt 7 ps 0.6", ...
  // Empty, or one standard deviation per point: the data get a third column and the series is
  // plotted `using 1:2:3` (give a style such as "yerrorbars pt 7").
  Eigen::VectorXd y_error = Eigen::VectorXd();
};

// A vertical line across the whole plot at x, labelled beside its top (an instant on a time axis).
struct VerticalMark {
  double x = 0;
  std::string label;
  std::string color = "#2ca02c";
};

// A 2-D figure drawn by gnuplot (Debian gnuplot-nox, pngcairo terminal). Axis labels carry the
// unit, e.g. "time, s".
struct Figure {
  std::string title;
  std::string x_label;
  std::string y_label;
  std::vector<PlotSeries> series;
  std::vector<VerticalMark> marks;
  bool log_y = false;
  bool log_x = false;
  bool pad_x = false;  // leave a margin at both ends of x (points on the edges stay visible)
  std::string key = "top right box opaque";  // gnuplot `set key` options
  std::string x_range, y_range;              // gnuplot ranges ("[0:*]"); empty = automatic
  int width_px = 1000;
  int height_px = 420;
};

// Draws `figure` into `png_path` (atomically: a failed plot leaves no file). Throws
// std::runtime_error naming gnuplot's complaint if it fails or is not installed. While a
// FigureBatch is alive on this thread, the figure is only added to it.
void DrawFigure(const Figure& figure, const std::string& png_path);

// Collects the figures DrawFigure is asked for on this thread while it lives, and draws them all
// in one gnuplot process at Draw(): one process start instead of one per figure. Figures not
// drawn when it ends are dropped (an exception unwound past the report). Batches nest: the
// innermost one collects.
class FigureBatch {
 public:
  FigureBatch();
  ~FigureBatch();
  FigureBatch(const FigureBatch&) = delete;
  FigureBatch& operator=(const FigureBatch&) = delete;

  void Add(const Figure& figure, const std::string& png_path);
  // Draws every figure added so far; each PNG is committed only if all were drawn. Throws as
  // DrawFigure does. With 2 figures or more and `processes` 2, two gnuplot processes draw
  // alternate figures at once; 1 draws them all in one (beside other work).
  void Draw(int processes = 2);
  // Draw in two halves: Start has the figures added so far drawn on threads of their own and
  // returns, so that the caller can write its other files meanwhile; Finish waits, commits the
  // PNGs if all were drawn and throws as Draw does (nothing to do without a Start). A drawing
  // not finished when the batch ends is waited for and its PNGs dropped.
  void Start(int processes = 2);
  void Finish();

 private:
  FigureBatch* outer_;
  std::vector<std::pair<Figure, std::string>> figures_;
  std::unique_ptr<internal::FigureDrawing> drawing_;
};

// What DrawFigure gives gnuplot: the data file (one block per series, separated by two blank
// lines) and the commands that draw it from `data_path` into `png_path`.
std::string GnuplotData(const Figure& figure);
std::string GnuplotCommands(const Figure& figure, const std::string& data_path,
                            const std::string& png_path);

// True if a gnuplot with the pngcairo terminal is on PATH; checked once per process.
bool GnuplotAvailable();

// Starts up to `processes` gnuplot processes (fewer if that many already wait) that set up their
// terminal at once and then wait for figures: the figures drawn later in this process skip
// gnuplot's start, about half of a figure's time. For figures whose drawing users wait for, such
// as `mbid run`'s last ones. Unused processes end with this one.
void PrepareGnuplot(int processes);

}  // namespace mbid::report
