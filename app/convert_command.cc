#include "app/convert_command.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <iomanip>
#include <memory>

#include "app/command_line.h"
#include "bridge/event_log.h"
#include "bridge/lcm_link.h"
#include "bridge/mcap_writer.h"
#include "scene/files.h"

namespace sandbox::app {
namespace {

const char* kUsage =
    "usage: sandbox convert IN OUT [--compression zstd|lz4|none]\n"
    "  a recording (an LCM log, `sandbox run --record`'s or lcm-logger's, or an MCAP file) to\n"
    "  MCAP when OUT ends in .mcap, else to an LCM log; every event, in order, with its time\n"
    "  --compression  the MCAP chunks' (default zstd)\n";

}  // namespace

int RunConvert(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) {
  std::vector<std::string> files, options;
  for (std::size_t i = 0; i < args.size(); ++i) {
    if (args[i] == "--compression" && i + 1 < args.size()) {
      options = {args[i], args[i + 1]};
      ++i;
    } else if (args[i] == "--help" || args[i] == "-h") {
      out << kUsage;
      return 0;
    } else if (args[i].rfind("--", 0) == 0) {
      err << "sandbox convert: unknown option '" << args[i] << "'\n" << kUsage;
      return 2;
    } else {
      files.push_back(args[i]);
    }
  }
  if (files.size() != 2) {
    err << "sandbox convert: give the file to read and the file to write\n" << kUsage;
    return 2;
  }
  const std::string& in_path = files[0];
  const std::string& out_path = files[1];
  std::string compression = options.empty() ? "zstd" : options[1];
  if (compression == "none") compression.clear();
  if (compression != "zstd" && compression != "lz4" && !compression.empty()) {
    err << "sandbox convert: --compression '" << options[1] << "': zstd, lz4 or none\n";
    return 2;
  }
  const bool to_mcap = out_path.size() >= 5 && out_path.substr(out_path.size() - 5) == ".mcap";
  if (!to_mcap && !options.empty()) {
    err << "sandbox convert: --compression is for an MCAP file (OUT ending in .mcap)\n";
    return 2;
  }
  std::error_code same_error;
  if (std::filesystem::equivalent(in_path, out_path, same_error)) {
    throw CommandError("'" + out_path + "' is the file to read");
  }

  const std::unique_ptr<bridge::EventReader> reader = bridge::OpenEventReader(in_path);
  std::unique_ptr<bridge::EventWriter> writer;
  if (to_mcap) {
    bridge::McapWriter::Options mcap;
    mcap.compression = compression;
    writer = std::make_unique<bridge::McapWriter>(out_path, mcap);
  } else {
    writer = std::make_unique<bridge::LogWriter>(out_path);
  }
  using Clock = std::chrono::steady_clock;
  auto next_report = Clock::now() + std::chrono::seconds(1);
  std::string channel;
  std::vector<std::uint8_t> data;
  std::int64_t utime = 0;
  while (reader->Next(&channel, &data, &utime)) {
    if (!writer->Write(channel, data.data(), unsigned(data.size()), utime)) break;
    if (reader->events() % 1024 == 0 && Clock::now() >= next_report) {
      err << "\rconvert: " << int(100.0 * reader->fraction_read()) << "% | " << reader->events()
          << " events" << std::flush;
      next_report = Clock::now() + std::chrono::seconds(1);
    }
  }
  const bool written = writer->Close();
  const auto in_bytes = scene::FileBytes(in_path), out_bytes = scene::FileBytes(out_path);
  out << "sandbox convert: " << writer->events() << " events from " << in_path << " to " << out_path
      << ", " << in_bytes << " -> " << out_bytes << " bytes (" << std::fixed << std::setprecision(3)
      << double(out_bytes) / double(std::max<std::uint64_t>(in_bytes, 1)) << "x)";
  if (reader->skipped() > 0) out << "; " << reader->skipped() << " skipped (not LCM messages)";
  out << "\n";
  if (!reader->stopped_early().empty()) {
    err << "sandbox convert: '" << in_path << "' is " << reader->stopped_early() << "; the "
        << reader->events() << " events before it were converted\n";
    return 1;
  }
  if (!written) {
    err << "sandbox convert: " << writer->error() << "\n";
    return 1;
  }
  return 0;
}

}  // namespace sandbox::app
