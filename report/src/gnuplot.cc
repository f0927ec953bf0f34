#include "mbid/report/gnuplot.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <future>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "gnuplot_standby.h"
#include "mbid/common/atomic_file.h"
#include "mbid/common/interrupt_cleanup.h"

namespace mbid::report {
namespace {

// A gnuplot string literal. Single quotes: gnuplot interprets backslash escapes in double-quoted
// strings and runs `backquoted` commands in anything but single-quoted ones; here only a quote
// needs doubling. A line break would end the command, so control characters become spaces.
std::string Quote(const std::string& text) {
  std::string quoted = "'";
  for (const char c : text) {
    if (c == '\'') quoted += '\'';
    quoted += static_cast<unsigned char>(c) < 0x20 || c == 0x7f ? ' ' : c;
  }
  return quoted + "'";
}

// Runs `arguments` (arguments[0] looked up on PATH) without a shell, so that nothing in them is
// interpreted, with standard input from /dev/null and standard output and error into
// `log_path`. Returns the wait status, or -1 with errno set when the program cannot start.
int Spawn(const std::vector<std::string>& arguments, const std::string& log_path) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log_path.c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  std::vector<char*> argv;
  for (const std::string& argument : arguments) argv.push_back(const_cast<char*>(argument.c_str()));
  argv.push_back(nullptr);
  pid_t pid = 0;
  const int error = internal::SpawnUnblocked(&pid, actions, argv.data());
  posix_spawn_file_actions_destroy(&actions);
  if (error != 0) {
    errno = error;
    return -1;
  }
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) return -1;
  }
  return status;
}

// The terminal of every figure; processes started ahead set it up for the default size.
std::string TerminalCommand(const Figure& figure) {
  return fmt::format("set terminal pngcairo size {},{} font 'Sans,10' noenhanced\n",
                     figure.width_px, figure.height_px);
}

// A path gnuplot cannot take for an option.
std::string AsArgument(const std::string& path) {
  return !path.empty() && path[0] == '-' ? "./" + path : path;
}

// Temporary files beside the figure, removed on every exit and on SIGINT/SIGTERM.
class ScratchFile {
 public:
  explicit ScratchFile(std::string path) : path_(std::move(path)), cleanup_(path_) {}
  ~ScratchFile() {
    std::error_code ignored;
    std::filesystem::remove(path_, ignored);
  }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  RemoveOnInterrupt cleanup_;
};

// A full disk shows only in the stream's state, after the last write is flushed.
void CheckWritten(std::ofstream& out, const std::string& path) {
  out.close();
  if (out.fail()) {
    throw std::runtime_error("cannot write " + path + ": " + std::strerror(errno) +
                             " (a full disk?)");
  }
}

}  // namespace

void PrepareGnuplot(int processes) {
  if (!GnuplotAvailable()) return;
  // The terminal of a figure of the default size, set up by drawing an empty plot into
  // /dev/null; `reset` leaves the terminal as it is.
  const std::string warm_up = TerminalCommand(Figure()) +
                              "set output '/dev/null'\n"
                              "set xrange [0:1]\nset yrange [0:1]\n"
                              "plot 0.5 notitle\n"
                              "unset output\nreset\n";
  internal::StartStandbyGnuplot(processes, warm_up);
}

bool GnuplotAvailable() {
  // Asked once per process: the check starts gnuplot (10-40 ms by the host), and `mbid run`
  // asks on its early figures' thread and again in the report, after the fit, where users wait.
  static const bool available = Spawn({"gnuplot", "-e", "set terminal pngcairo"}, "/dev/null") == 0;
  return available;
}

namespace {

// The batch that DrawFigure adds to on this thread, if any.
thread_local FigureBatch* active_batch = nullptr;

void WriteData(const Figure& figure, const std::string& path) {
  std::ofstream out(path);
  out << GnuplotData(figure);
  CheckWritten(out, path);
}

std::string ReadLog(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// Draws `figures` in one gnuplot process into their PNGs' temporary names, committed by the
// caller: a process start and the cairo set-up cost about as much as drawing a figure
// (docs/performance.md).
std::vector<std::unique_ptr<AtomicFile>> DrawGroup(
    const std::vector<std::pair<Figure, std::string>>& figures) {
  std::vector<std::unique_ptr<AtomicFile>> pngs;
  std::vector<std::unique_ptr<ScratchFile>> scratch;
  for (const auto& [figure, png_path] : figures) {
    pngs.push_back(std::make_unique<AtomicFile>(png_path));
    scratch.push_back(std::make_unique<ScratchFile>(pngs.back()->temp_path() + ".dat"));
    WriteData(figure, scratch.back()->path());
  }
  const std::string& first = pngs.front()->temp_path();
  const ScratchFile script_file(first + ".gp");
  const ScratchFile log(first + ".log");
  {
    std::ofstream script(script_file.path());
    for (size_t i = 0; i < figures.size(); ++i) {
      script << GnuplotCommands(figures[i].first, scratch[i]->path(), pngs[i]->temp_path());
    }
    CheckWritten(script, script_file.path());
  }
  const std::string& named = figures.front().second;
  const std::string what =
      figures.size() == 1 ? named
                          : fmt::format("{} and {} other figure(s)", named, figures.size() - 1);
  std::string messages;
  int status = -1;
  if (const std::optional<internal::StandbyGnuplot> standby = internal::TakeStandbyGnuplot()) {
    status = internal::RunStandby(*standby, "load " + Quote(script_file.path()), &messages);
  }
  if (status < 0) {
    messages.clear();
    status = Spawn({"gnuplot", AsArgument(script_file.path())}, log.path());
    if (status < 0) {
      throw std::runtime_error("cannot start gnuplot for " + what + ": " + std::strerror(errno));
    }
    messages = ReadLog(log.path());
  }
  if (status != 0) throw std::runtime_error("gnuplot failed on " + what + ": " + messages);
  for (size_t i = 0; i < figures.size(); ++i) {
    std::error_code ignored;
    if (std::filesystem::file_size(pngs[i]->temp_path(), ignored) == 0 || ignored) {
      // gnuplot reports a failed write of its output on standard error but exits with 0.
      const std::string& text = messages;
      throw std::runtime_error("cannot write " + figures[i].second + ": gnuplot wrote no figure (" +
                               (text.empty() ? "no message" : text) + ")");
    }
  }
  return pngs;
}

using Drawn = std::vector<std::unique_ptr<AtomicFile>>;

}  // namespace

// Figures drawn by one or two gnuplot processes, each group on a thread of its own, so that the
// caller can go on meanwhile; each PNG is committed only when all were drawn.
struct internal::FigureDrawing {
  std::vector<std::future<Drawn>> groups;

  FigureDrawing(const std::vector<std::pair<Figure, std::string>>& figures, int processes) {
    if (figures.empty()) return;
    // A gnuplot start costs 10 ms on a quiet host, a figure 15-20 ms: two figures already pay
    // for the second process (mbid run's last three: 85 -> 65 ms, docs/performance.md).
    constexpr size_t kParallelFrom = 2;
    const size_t count = figures.size() < kParallelFrom || processes < 2 ? 1 : 2;
    for (size_t g = 0; g < count; ++g) {
      std::vector<std::pair<Figure, std::string>> group;
      for (size_t i = g; i < figures.size(); i += count) group.push_back(figures[i]);
      groups.push_back(std::async(std::launch::async, DrawGroup, std::move(group)));
    }
  }

  // Waits for every group (their threads must end before anything is thrown) and commits.
  void Finish() {
    std::vector<Drawn> drawn;
    std::exception_ptr error;
    for (std::future<Drawn>& group : groups) {
      try {
        drawn.push_back(group.get());
      } catch (...) {
        if (!error) error = std::current_exception();
      }
    }
    groups.clear();
    if (error) std::rethrow_exception(error);
    for (const Drawn& pngs : drawn) {
      for (const auto& png : pngs) png->Commit();
    }
  }
};

namespace {

void DrawAll(const std::vector<std::pair<Figure, std::string>>& figures, int processes = 2) {
  internal::FigureDrawing(figures, processes).Finish();
}

}  // namespace

std::string GnuplotData(const Figure& figure) {
  // One data block per series, separated by two blank lines (gnuplot's "index").
  std::string data;
  for (const PlotSeries& series : figure.series) {
    const bool with_error = series.y_error.size() == series.x.size() && series.x.size() > 0;
    for (Eigen::Index i = 0; i < series.x.size(); ++i) {
      data += with_error ? fmt::format("{:.10g} {:.10g} {:.10g}\n", series.x[i], series.y[i],
                                       series.y_error[i])
                         : fmt::format("{:.10g} {:.10g}\n", series.x[i], series.y[i]);
    }
    data += "\n\n";
  }
  return data;
}

// The commands of one figure; `reset` first, so that nothing of the figure before carries over.
std::string GnuplotCommands(const Figure& figure, const std::string& data_path,
                            const std::string& png_path) {
  std::ostringstream script;
  script << "reset\n";
  script << TerminalCommand(figure);
  script << "set output " << Quote(png_path) << "\n";
  script << "set title " << Quote(figure.title) << "\n";
  script << "set xlabel " << Quote(figure.x_label) << "\n";
  script << "set ylabel " << Quote(figure.y_label) << "\n";
  script << "set grid\nset key " << figure.key << "\nset offsets 0, 0, graph 0.05, graph 0.05\n";
  if (figure.log_y) script << "set logscale y\nset format y '%.0e'\n";
  if (figure.log_x) script << "set logscale x\nset format x '%g'\n";
  if (!figure.x_range.empty()) script << "set xrange " << figure.x_range << "\n";
  if (!figure.y_range.empty()) script << "set yrange " << figure.y_range << "\n";
  if (figure.pad_x) script << "set offsets graph 0.03, graph 0.03, graph 0.05, graph 0.05\n";
  // A mark spans the plot whatever its y range: x in data coordinates, y in the graph's.
  for (const VerticalMark& mark : figure.marks) {
    script << fmt::format(
        "set arrow from first {0:.10g}, graph 0 to first {0:.10g}, graph 1 nohead dt 2 lw 1.5 "
        "lc rgb {1} front\n",
        mark.x, Quote(mark.color));
    script << fmt::format(
        "set label {} at first {:.10g}, graph 0.96 left offset 0.6, 0 tc rgb {} "
        "front\n",
        Quote(mark.label), mark.x, Quote(mark.color));
  }
  script << "plot ";
  for (size_t k = 0; k < figure.series.size(); ++k) {
    const PlotSeries& series = figure.series[k];
    const bool with_error = series.y_error.size() == series.x.size() && series.x.size() > 0;
    if (k > 0) script << ", \\\n     ";
    script << Quote(data_path) << " index " << k << (with_error ? " using 1:2:3" : " using 1:2")
           << " with " << series.style << " title " << Quote(series.title);
  }
  // Closing the output completes the file before the next figure opens its own.
  script << "\nunset output\n";
  return script.str();
}

void DrawFigure(const Figure& figure, const std::string& png_path) {
  if (active_batch != nullptr) {
    active_batch->Add(figure, png_path);
    return;
  }
  DrawAll({{figure, png_path}});
}

FigureBatch::FigureBatch() : outer_(active_batch) { active_batch = this; }

// A drawing not finished is waited for here (std::future's destructor) and its PNGs dropped.
FigureBatch::~FigureBatch() { active_batch = outer_; }

void FigureBatch::Add(const Figure& figure, const std::string& png_path) {
  figures_.emplace_back(figure, png_path);
}

void FigureBatch::Draw(int processes) {
  Start(processes);
  Finish();
}

void FigureBatch::Start(int processes) {
  Finish();
  std::vector<std::pair<Figure, std::string>> figures;
  figures.swap(figures_);
  drawing_ = std::make_unique<internal::FigureDrawing>(figures, processes);
}

void FigureBatch::Finish() {
  if (!drawing_) return;
  const std::unique_ptr<internal::FigureDrawing> drawing = std::move(drawing_);
  drawing->Finish();
}

}  // namespace mbid::report
