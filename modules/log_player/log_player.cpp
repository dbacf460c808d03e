// log_player: plays a data_logger log (or a flight-recorder dump's variables.csv) back into state
// variables, row by row on the subsystem's clock: the counterpart of data_logger.

#include "module_docs/log_player.hpp"

#include <cerrno>
#include <cmath>
#include <cstddef>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "chimera/module/registry.hpp"
#include "support/module_support.hpp"

namespace chimera::modules {
namespace {

// A log is read whole in init: a bound on it keeps a wrong file from taking the machine's memory.
constexpr std::uintmax_t kMostFileBytes = std::uintmax_t{512} << 20;

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> cells;
  std::size_t from = 0;
  for (std::size_t comma = line.find(','); comma != std::string::npos; comma = line.find(',', from)) {
    cells.push_back(line.substr(from, comma - from));
    from = comma + 1;
  }
  cells.push_back(line.substr(from));
  return cells;
}

class LogPlayer final : public Module {
 public:
  static constexpr const char* kName = "log_player";
  static constexpr const char* kSummary = docs::log_player::kSummary;
  static constexpr const char* kDoc = docs::log_player::kText;

  static void declare(Declarations& d, const Params& p) {
    for (const auto& v : p.strings("variables"))
      d.out_var(v, Dim::follow(), "the log's columns v[0], v[1], ... each row");
    d.param("variables", StringList{}, "", "state variables to play (one out-var port each), columns of the log");
    d.param("file", std::string(), "", "the log (CSV, header t,v[0],...); relative: below $CHIMERA_LOG_DIR if set");
    d.param("from", 0.0, "s", "the log's time played at the subsystem's time 0");
    d.resource("a CSV file, read whole in init");
  }

 protected:
  Status init(InitContext& ctx) override {
    const auto names = ctx.params().strings("variables");
    if (names.empty()) return ctx.refuse("variables", "give variables: [names] to play");
    for (const auto& name : names) outs_.push_back(ctx.out<double>(name));
    if (ctx.failed()) return Status::ok();             // an unbound view already fails init, naming the port
    path_ = log_file_path(ctx.params().text("file"));  // where data_logger writes it
    from_s_ = ctx.params().number("from", 0.0);
    timing_ = &ctx.timing();
    const Status read = read_log(names);
    return read.is_ok() ? read : ctx.refuse("file", read.reason());
  }

  Status on() override {
    next_ = 0;  // each on plays from the subsystem's time on, wherever that is in the log
    return Status::ok();
  }

  Status cycle() override {
    // A row of this very instant is due: its time and the release's, each in seconds as a double,
    // can differ in the last bits (0.699 + 0.064 is not 0.763), so a row is due up to 100 ns
    // early, far below any period (10 us at least). Without it a row now and then played a
    // release late.
    constexpr double kSameInstantS = 1e-7;
    const double t = static_cast<double>(timing_->release_ns) * 1e-9 + from_s_ + kSameInstantS;
    std::size_t row = next_;
    while (row < times_.size() && times_[row] <= t) ++row;
    if (row == next_) return Status::ok();  // no row came due (or the log has not begun): the outputs hold
    next_ = row;
    const double* values = &rows_[(row - 1) * width_];
    for (std::size_t v = 0, column = 0; v < outs_.size(); ++v)
      for (std::size_t e = 0; e < outs_[v].size(); ++e, ++column)
        if (!std::isnan(values[column])) outs_[v][e] = values[column];  // nan: not written yet then
    return Status::ok();
  }

 private:
  // Reads the whole log: the columns of `names` (each name[0] .. name[n-1], n its port's size),
  // in rows of width_ values. Every refusal names the file and, past the header, the line.
  Status read_log(const std::vector<std::string>& names) {
    std::error_code ec;
    const auto bytes = std::filesystem::file_size(path_, ec);
    if (ec || !std::filesystem::is_regular_file(path_, ec))
      return Status::fail(intern(fmt::format("{}: cannot read the log: {}", path_, ec ? ec.message() : "not a file")));
    if (bytes > kMostFileBytes)
      return Status::fail(
          intern(fmt::format("{}: {} bytes, over the {} MiB a log may have", path_, bytes, kMostFileBytes >> 20)));
    std::ifstream in(path_);
    std::string line;
    if (!std::getline(in, line)) return Status::fail(intern(fmt::format("{}:1: the file is empty", path_)));
    const auto header = split(line);
    if (header.empty() || header[0] != "t")
      return Status::fail(intern(fmt::format("{}:1: the first column is not t (is this a data_logger log?)", path_)));
    std::vector<std::size_t> columns;  // of the file, in play order
    for (std::size_t v = 0; v < names.size(); ++v)
      for (std::size_t e = 0; e < outs_[v].size(); ++e) {
        const std::string want = fmt::format("{}[{}]", names[v], e);
        std::size_t at = 0;
        while (at < header.size() && header[at] != want) ++at;
        if (at == header.size())
          return Status::fail(intern(
              fmt::format("{}:1: no column {} ({} has {} elements here)", path_, want, names[v], outs_[v].size())));
        columns.push_back(at);
      }
    width_ = columns.size();
    for (std::size_t number = 2; std::getline(in, line); ++number) {
      if (line.empty()) continue;
      const auto cells = split(line);
      if (cells.size() != header.size())
        return Status::fail(
            intern(fmt::format("{}:{}: {} cells, the header has {}", path_, number, cells.size(), header.size())));
      const auto number_of = [&](const std::string& cell, double& out) {
        char* end = nullptr;
        errno = 0;
        out = std::strtod(cell.c_str(), &end);
        return end != cell.c_str() && *end == '\0' && errno == 0;
      };
      double t = 0;
      if (!number_of(cells[0], t) || (!times_.empty() && t < times_.back()))
        return Status::fail(
            intern(fmt::format("{}:{}: t is '{}', not a time at or after the row before", path_, number, cells[0])));
      times_.push_back(t);
      for (const std::size_t c : columns) {
        double value = 0;
        if (!number_of(cells[c], value))
          return Status::fail(
              intern(fmt::format("{}:{}: '{}' in column {} is not a number", path_, number, cells[c], header[c])));
        rows_.push_back(value);
      }
    }
    if (times_.empty()) return Status::fail(intern(fmt::format("{}: the log has no rows", path_)));
    return Status::ok();
  }

  const CycleTiming* timing_ = nullptr;
  std::vector<Out<double>> outs_;
  std::string path_;
  double from_s_ = 0;
  std::vector<double> times_;  // of each row, s
  std::vector<double> rows_;   // width_ values a row, the outputs' elements in order
  std::size_t width_ = 0;
  std::size_t next_ = 0;  // rows before it have come due
};

CHIMERA_REGISTER_MODULE(LogPlayer);

}  // namespace
}  // namespace chimera::modules
