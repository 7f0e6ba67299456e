#include "suite/pipeline_bench.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "cl/cl_runtime.h"
#include "common/cpu_load.h"
#include "common/stats.h"
#include "core/atomic_file.h"
#include "core/child_process.h"
#include "core/error.h"
#include "phantom/phantom.h"

namespace pneumo::bench {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

// The stages metrics.json times (pipeline/simulate.cpp, run.cpp), in the order they run.
const char* const kStages[] = {"roles", "mesh", "solve", "warp", "render", "report"};

std::string read_text(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string last_line(const std::string& text) {
  std::string t = text;
  while (!t.empty() && (t.back() == '\n' || t.back() == '\r')) t.pop_back();
  const auto nl = t.find_last_of('\n');
  return nl == std::string::npos ? t : t.substr(nl + 1);
}

/// Seconds from `start` to the earliest PNG under out/views (the first view on disk); −1 when there is none.
double first_view_s(const fs::path& out, fs::file_time_type start) {
  std::error_code ec;
  if (!fs::is_directory(out / "views", ec)) return -1.0;
  double best = -1.0;
  for (const auto& e : fs::directory_iterator(out / "views", ec)) {
    if (e.path().extension() != ".png") continue;
    const double s = std::chrono::duration<double>(fs::last_write_time(e.path(), ec) - start).count();
    if (!ec && (best < 0.0 || s < best)) best = s;
  }
  return best;
}

struct RunSample {
  bool ok = false;
  std::string error;
  double wall_s = 0, first_view_s = -1, other_cores = -1;
  std::map<std::string, double> stage_s;
};

/// One `pneumo run` as a new process, timed from its start; its output goes to a log beside its folder.
RunSample run_once(const fs::path& exe, const fs::path& scene, const fs::path& out, const std::string& device) {
  RunSample r;
  const fs::path log = out.string() + ".log";
  const fs::file_time_type start_file = fs::file_time_type::clock::now();
  const auto t0 = std::chrono::steady_clock::now();
  const CpuSample a = cpu_sample();
  // An argument vector, never a shell: the folders' names reach pneumo as they are.
  const int status = run_program({exe.string(), "-q", "run", scene.string(), "--out", out.string(), "--force",
                                  "--device", device},
                                 log.string());
  const CpuSample b = cpu_sample();
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.other_cores = other_cores(a, b);   // the child, waited for, counts as this process's own
  if (status != 0) {
    r.error = "pneumo run exited with status " + std::to_string(status) + ": " + last_line(read_text(log));
    return r;
  }
  const json m = json::parse(read_text(out / "metrics.json"), nullptr, false);
  if (m.is_discarded() || !m.contains("stage_seconds")) {
    r.error = "no stage_seconds in " + (out / "metrics.json").string();
    return r;
  }
  for (const char* s : kStages)
    if (m["stage_seconds"].contains(s)) r.stage_s[s] = m["stage_seconds"][s].get<double>();
  r.first_view_s = first_view_s(out, start_file);
  r.ok = true;
  return r;
}

json summarise_samples(const std::vector<RunSample>& samples) {
  std::vector<double> wall, first, other;
  std::map<std::string, std::vector<double>> stages;
  for (const RunSample& s : samples) {
    if (!s.ok) continue;
    wall.push_back(s.wall_s);
    if (s.first_view_s >= 0) first.push_back(s.first_view_s);
    if (s.other_cores >= 0) other.push_back(s.other_cores);
    for (const auto& [k, v] : s.stage_s) stages[k].push_back(v);
  }
  json j;
  j["runs"] = samples.size();
  j["completed"] = wall.size();
  j["wall_s"] = to_json(summarize(wall));
  j["first_view_s"] = to_json(summarize(first));
  j["other_cores"] = to_json(summarize(other));
  for (const auto& [k, v] : stages) j["stage_s"][k] = to_json(summarize(v));
  json errors = json::array();
  for (const RunSample& s : samples)
    if (!s.ok) errors.push_back(s.error);
  j["errors"] = errors;
  return j;
}

}  // namespace

json run_pipeline_bench(const PipelineBenchOptions& opt) {
  if (!opt.json_path.empty()) check_writable_target(opt.json_path);
  if (!opt.markdown_path.empty()) check_writable_target(opt.markdown_path);
  const fs::path exe = fs::read_symlink("/proc/self/exe");
  // The phantoms' files and the runs' folders (up to a few GB for the large phantom), removed however this ends.
  struct Scratch {
    fs::path path = fs::temp_directory_path() / ("pneumo_pipeline_bench_" + std::to_string(::getpid()));
    Scratch() { fs::remove_all(path), fs::create_directories(path); }
    ~Scratch() {
      std::error_code ec;
      fs::remove_all(path, ec);
    }
  } scratch_dir;
  const fs::path& scratch = scratch_dir.path;

  const std::vector<PhantomSize> sizes =
      opt.quick ? std::vector<PhantomSize>{PhantomSize::Small} : std::vector<PhantomSize>{PhantomSize::Medium, PhantomSize::Large};
  const std::vector<std::string> presets =
      opt.quick ? std::vector<std::string>{"preview"} : std::vector<std::string>{"preview", "balanced"};
  std::vector<std::string> devices{"cpu"};
  if (!opt.quick)
    for (const ocl::DeviceInfo& d : ocl::list_devices()) devices.push_back(d.spec());
  const int reps = opt.quick ? 1 : 3;

  json doc;
  doc["schema"] = "pneumo-bench-pipeline/1";
  doc["pneumo_version"] = PNEUMO_VERSION;
  doc["quick"] = opt.quick;
  doc["repetitions"] = reps;
  doc["logical_cpus"] = ::sysconf(_SC_NPROCESSORS_ONLN);
  doc["load_average_start"] = to_json(load_average());
  doc["anchors"] = json::array(
      {{{"what", "Nimura 2015 (dual Xeon 3.33 GHz)"}, {"seconds", 150.0 * 60.0}},
       {{"what", "Kitasaka 2004 (a Pentium PC)"}, {"seconds", 75.0 * 60.0}}});
  doc["how"] = "Each row: `pneumo -q run` started as a new process on the phantom's files with the scene's "
               "\"preset\" and --device set; first view = the earliest PNG in views/ after the start; stages from "
               "metrics.json stage_seconds; medians over the repetitions with min and max; other_cores = CPU other "
               "processes used meanwhile (all CPUs' busy time less the run's own).";
  const auto t_all = std::chrono::steady_clock::now();
  json cases = json::array();
  for (const PhantomSize size : sizes) {
    const fs::path dir = scratch / phantom_size_name(size);
    std::fprintf(stderr, "[bench] pipeline: writing the %s phantom\n", phantom_size_name(size));
    write_phantom_case(make_phantom(size), size, dir.string());
    json scene = json::parse(read_text(dir / "scene.json"));
    json c;
    c["case"] = std::string(phantom_size_name(size)) + " phantom";
    const Geometry g = phantom_geometry(size);
    c["grid"] = {g.dims[0], g.dims[1], g.dims[2]};
    c["voxel_mm"] = g.spacing_mm.maxCoeff();
    json rows = json::array();
    for (const std::string& preset : presets) {
      scene["preset"] = preset;
      const fs::path scene_path = dir / ("scene_" + preset + ".json");
      write_text_file_atomic(scene_path.string(), scene.dump(2) + "\n");
      for (const std::string& device : devices) {
        std::vector<RunSample> samples;
        for (int k = 0; k < reps; ++k) {
          std::fprintf(stderr, "[bench] pipeline: %s, %s, %s, run %d/%d\n", phantom_size_name(size), preset.c_str(),
                       device.c_str(), k + 1, reps);
          const fs::path out = dir / ("run_" + preset + "_" + std::to_string(rows.size()));
          samples.push_back(run_once(exe, scene_path, out, device));
          fs::remove_all(out);
        }
        json row = summarise_samples(samples);
        row["preset"] = preset;
        row["device"] = device;
        rows.push_back(row);
      }
    }
    c["rows"] = rows;
    cases.push_back(c);
    fs::remove_all(dir);
  }
  doc["cases"] = cases;
  doc["load_average_end"] = to_json(load_average());
  doc["wall_time_s"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_all).count();
  if (!opt.json_path.empty()) write_text_file_atomic(opt.json_path, doc.dump(2) + "\n");
  if (!opt.markdown_path.empty()) write_text_file_atomic(opt.markdown_path, pipeline_bench_markdown(doc));
  return doc;
}

std::string pipeline_bench_markdown(const json& doc) {
  const auto cell = [](const json& s) {
    if (!s.is_object() || s.value("n", 0) == 0) return std::string("—");
    char b[64];
    std::snprintf(b, sizeof b, "%.1f (%.1f–%.1f)", s["median"].get<double>(), s["min"].get<double>(), s["max"].get<double>());
    return std::string(b);
  };
  std::ostringstream md;
  md << "# pneumo bench --pipeline\n\nA CT file to the first laparoscope view, as a user runs it: `pneumo run` as a new "
        "process per row, seconds, median (min–max) over "
     << doc["repetitions"].get<int>() << (doc["repetitions"] == 1 ? " run" : " runs") << ". " << doc.value("how", "") << "\n\n";
  const json& l0 = doc["load_average_start"];
  const json& l1 = doc["load_average_end"];
  char load[160];
  std::snprintf(load, sizeof load, "Load average (1, 5, 15 min) at the start %.2f, %.2f, %.2f; at the end %.2f, %.2f, %.2f; ",
                l0[0].get<double>(), l0[1].get<double>(), l0[2].get<double>(), l1[0].get<double>(), l1[1].get<double>(),
                l1[2].get<double>());
  md << load << doc["logical_cpus"] << " logical CPUs; the whole run " << int(doc["wall_time_s"].get<double>())
     << " s.\n\n";
  for (const json& c : doc["cases"]) {
    md << "## " << c["case"].get<std::string>() << " (" << c["grid"][0] << "×" << c["grid"][1] << "×" << c["grid"][2]
       << " at " << c["voxel_mm"].get<double>() << " mm)\n\n";
    md << "| preset | device | first view | total | roles | mesh | solve | warp | render | report | other cores |\n"
          "|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const json& r : c["rows"]) {
      md << "| " << r["preset"].get<std::string>() << " | " << r["device"].get<std::string>() << " | "
         << cell(r["first_view_s"]) << " | " << cell(r["wall_s"]);
      for (const char* s : kStages) md << " | " << (r["stage_s"].contains(s) ? cell(r["stage_s"][s]) : "—");
      md << " | " << cell(r["other_cores"]) << " |\n";
      for (const json& e : r["errors"]) md << "\n*" << r["preset"].get<std::string>() << " on " << r["device"].get<std::string>() << ": " << e.get<std::string>() << "*\n";
    }
    md << "\n";
  }
  md << "Anchors, for the deformation alone: ";
  bool first = true;
  for (const json& a : doc["anchors"]) {
    md << (first ? "" : "; ") << a["what"].get<std::string>() << ", " << int(a["seconds"].get<double>() / 60) << " min";
    first = false;
  }
  md << ".\n";
  return md.str();
}

}  // namespace pneumo::bench
