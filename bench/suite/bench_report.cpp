#include "suite/bench_report.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <sstream>

#include "core/atomic_file.h"
#include "report/plot_svg.h"

namespace pneumo::bench {

namespace {

using json = nlohmann::json;

std::string fmt(const char* f, double v) {
  char b[64];
  std::snprintf(b, sizeof b, f, v);
  return b;
}

/// "median (min–max)" of a summary, scaled and formatted.
std::string spread(const json& s, double scale = 1.0, const char* f = "%.3g") {
  if (!s.is_object() || !s.contains("median")) return "–";
  return fmt(f, s["median"].get<double>() * scale) + " (" + fmt(f, s["min"].get<double>() * scale) + "–" +
         fmt(f, s["max"].get<double>() * scale) + ")";
}

std::string num(const json& v, const char* f = "%.3g", double scale = 1.0) {
  return v.is_number() ? fmt(f, v.get<double>() * scale) : "–";
}

void machine(std::ostringstream& md, const json& doc) {
  const json& m = doc["machine"];
  md << "## Machine and load\n\n";
  md << "- CPU: " << m["cpu_model"].get<std::string>() << ", " << m["logical_cpus"] << " logical CPUs, OpenMP "
     << m["openmp_threads"] << " threads, " << num(m["memory_gib"], "%.0f") << " GiB\n";
  for (const auto& d : m["opencl_devices"])
    md << "- OpenCL " << d["spec"].get<std::string>() << ": " << d["name"].get<std::string>() << " ("
       << d["platform"].get<std::string>() << ", " << d["compute_units"] << " compute units)\n";
  if (m["gl"].contains("renderer"))
    md << "- OpenGL: " << m["gl"]["renderer"].get<std::string>() << ", " << m["gl"]["version"].get<std::string>()
       << " (" << m["gl"]["backend"].get<std::string>() << ")\n";
  const auto load = [](const json& l) {
    return num(l[0], "%.2f") + ", " + num(l[1], "%.2f") + ", " + num(l[2], "%.2f");
  };
  md << "- Load average (1, 5, 15 min) at the start: " << load(m["load_average_start"]) << "; at the end: "
     << load(m["load_average_end"]) << "; other processes used " << num(doc["other_cores_mean"], "%.2f")
     << " cores on average during the run (the machine is shared)\n";
  md << "- Wall time of the whole run: " << num(doc["wall_time_s"], "%.0f") << " s" << (doc["quick"].get<bool>() ? " (--quick)" : "")
     << "; " << doc["date_utc"].get<std::string>() << ", pneumo " << doc["pneumo_version"].get<std::string>() << "\n\n";
  md << "Bandwidth (STREAM triad in this run; every roofline ratio below divides by its device's figure):\n\n";
  md << "| device | median GB/s | min–max | arrays |\n|---|---|---|---|\n";
  for (auto it = doc["bandwidth"].begin(); it != doc["bandwidth"].end(); ++it)
    md << "| " << it.key() << " | " << num((*it)["median_gb_s"], "%.1f") << " | " << num((*it)["min_gb_s"], "%.1f")
       << "–" << num((*it)["max_gb_s"], "%.1f") << " | " << num((*it)["bytes_per_array"], "%.0f", 1.0 / (1 << 20))
       << " MiB |\n";
  md << "\n";
}

void throughput(std::ostringstream& md, const json& doc) {
  md << "## Stages on every device\n\nMedians over repetitions, (min–max) beside them. Node updates: nodes × force "
        "evaluations (forces) or × explicit steps (step, the integrator included). Roofline: the achieved rate over "
        "min(bandwidth / bytes, peak / FLOPs) of the same device (bytes and FLOPs per node-update counted from the "
        "data structures, bench/common/solver_cost.h; the warp's bytes per voxel in bench/common/warp_cost.h). "
        "End to end: roles + mesh (CPU, once) + solve + warp + uploading the deformed CT and rendering one frame.\n\n";
  for (const auto& c : doc["throughput"]) {
    md << "### " << c["case"].get<std::string>() << ": " << c["grid"][0] << "×" << c["grid"][1] << "×" << c["grid"][2]
       << " voxels at " << num(c["spacing_mm"][0], "%.2f") << " mm, L = " << c["cube_voxels"] << ", " << c["nodes"]
       << " nodes, " << c["springs"] << " springs; peak memory " << num(c["peak_rss_mib"], "%.0f") << " MiB\n\n";
    md << "| device | force evals/s | node updates/s (forces) | roofline | node updates/s (step) | roofline | solve s "
          "| warp Mvoxel/s | roofline | end to end s | other cores |\n|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const auto& d : c["devices"]) {
      if (d.contains("error")) {
        md << "| " << d["device"].get<std::string>() << " | failed: " << d["error"].get<std::string>()
           << " |||||||||| \n";
        continue;
      }
      md << "| " << d["device"].get<std::string>() << " | " << spread(d["forces"]["force_evals_per_s"]) << " | "
         << spread(d["forces"]["node_updates_per_s"], 1e-6, "%.3gM") << " | "
         << num(d["forces"]["roofline"]["fraction"], "%.2f") << " "
         << d["forces"]["roofline"]["bound"].get<std::string>() << " | "
         << spread(d["explicit_step"]["node_updates_per_s"], 1e-6, "%.3gM") << " | "
         << num(d["explicit_step"]["roofline"]["fraction"], "%.2f") << " | " << spread(d["solve"]["seconds"]) << " | "
         << spread(d["warp"]["voxels_per_s"], 1e-6) << " | " << num(d["warp"]["roofline"]["fraction"], "%.2f")
         << " | " << spread(d["end_to_end_s"]) << " | " << num(d["other_cores"], "%.2f") << " |\n";
    }
    const json& r = c["render"];
    md << "\nRender: ";
    if (r.contains("gl"))
      md << "GL (" << r["gl"]["renderer"].get<std::string>() << ") " << r["gl"]["width"] << "×" << r["gl"]["height"]
         << ": " << spread(r["gl"]["frames_per_s"]) << " frames/s";
    if (r.contains("cpu_reference"))
      for (const auto& cr : r["cpu_reference"])
        md << "; CPU reference " << cr["device"].get<std::string>() << " " << cr["width"] << "×" << cr["height"]
           << ": " << spread(cr["frames_per_s"]) << " frames/s";
    md << ". " << r["roofline_note"].get<std::string>() << ".\n\n";
  }
}

void speed_accuracy(std::ostringstream& md, const json& sa, const std::string& plot) {
  md << "## Speed against accuracy\n\nThe " << sa["phantom"].get<std::string>() << " phantom ("
     << num(sa["voxel_mm"], "%.2f") << " mm voxels), CPU reference on all threads. Reference: "
     << sa["reference"]["solver"].get<std::string>() << ", " << num(sa["reference"]["cube_mm"], "%g") << " mm cubes, "
     << sa["reference"]["setting"].get<std::string>() << " " << num(sa["reference"]["value"], "%g") << " ("
     << num(sa["reference"]["wall_s"], "%.1f") << " s, " << sa["reference"]["nodes"] << " nodes). "
     << sa["error_definition"].get<std::string>() << ". " << sa["skin_points"] << " skin and " << sa["cavity_points"]
     << " cavity points. Runs stop at " << num(sa["time_limit_s"], "%g") << " s. Pareto: on the front of wall time "
     << "against RMS error.\n\n";
  md << "| solver | cube | setting | wall s | steps | converged | RMS error mm | skin RMS / max mm | cavity RMS / max mm "
        "| warp MAD HU (all / moved) | Pareto |\n|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& r : sa["runs"]) {
    md << "| " << r["solver"].get<std::string>() << " | " << num(r["cube_mm"], "%g") << " mm (L " << r["cube_voxels"]
       << ") | " << r["setting"].get<std::string>() << " " << num(r["value"], "%g") << " | " << num(r["wall_s"], "%.2f")
       << " | " << (r.contains("steps") ? std::to_string(r["steps"].get<int64_t>()) : "–") << " | "
       << (r["timed_out"].get<bool>() ? "time limit" : r["error"].is_string() ? "diverged" : r["converged"].get<bool>() ? "yes" : "no")
       << " | " << num(r["rms_error_mm"], "%.3f") << " | ";
    if (r.contains("skin"))
      md << num(r["skin"]["rms_mm"], "%.3f") << " / " << num(r["skin"]["max_mm"], "%.2f") << " | "
         << num(r["cavity"]["rms_mm"], "%.3f") << " / " << num(r["cavity"]["max_mm"], "%.2f") << " | "
         << num(r["warp_mad_hu"], "%.2f") << " / " << num(r["warp_mad_hu_moving"], "%.1f");
    else
      md << "– | – | –";
    md << " | " << (r["pareto"].get<bool>() ? "**yes**" : "") << " |\n";
  }
  md << "\n![wall time against displacement error](" << plot << ")\n\n";
  md << "Presets the front implies (fastest converged run within each error bound):\n\n";
  for (const auto& p : sa["implied_presets"]) {
    md << "- **" << p["name"].get<std::string>() << "** (" << p["rule"].get<std::string>() << "): ";
    if (p["run"].is_null()) md << "no run qualifies\n";
    else
      md << p["run"]["solver"].get<std::string>() << ", " << num(p["run"]["cube_mm"], "%g") << " mm cubes, "
         << p["run"]["setting"].get<std::string>() << " " << num(p["run"]["value"], "%g") << ": "
         << num(p["run"]["wall_s"], "%.2f") << " s, RMS error " << num(p["run"]["rms_error_mm"], "%.3f") << " mm\n";
  }
  md << "\nThe scene's presets (`\"preset\"` in a scene; host/scene/scene_presets.cpp) as measured in this run:\n\n";
  for (const auto& p : sa["scene_presets"]) {
    md << "- **" << p["name"].get<std::string>() << "**: " << p["solver"].get<std::string>() << ", "
       << num(p["cube_mm"], "%g") << " mm cubes, tolerance " << num(p["residual_tolerance"], "%g") << ": ";
    if (p["run"].is_null()) md << "not in this run's grid\n";
    else
      md << num(p["run"]["wall_s"], "%.2f") << " s, RMS error " << num(p["run"]["rms_error_mm"], "%.3f")
         << " mm (skin max " << num(p["run"]["skin"]["max_mm"], "%.2f") << " mm, warp MAD "
         << num(p["run"]["warp_mad_hu_moving"], "%.1f") << " HU where it moved)\n";
  }
  md << "\n";
}

void stability(std::ostringstream& md, const json& st) {
  md << "## Stability map\n\nThe " << st["phantom"].get<std::string>() << " phantom, CPU reference. "
     << st["method"].get<std::string>() << " (" << st["steps_per_trial"] << " steps per trial, " << st["bisections"]
     << " bisections). Estimate: method.md §6 (stable_time_step).\n\n";
  md << "| solver | cube | E kPa | nodes | estimate ms | largest stable ms | smallest unstable ms | stable / estimate "
        "| confirmed |\n|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& r : st["rows"])
    md << "| " << r["solver"].get<std::string>() << " | " << num(r["cube_mm"], "%g") << " mm | "
       << num(r["young_kpa"], "%g") << " | " << r["nodes"] << " | " << num(r["dt_estimate_ms"], "%.4f") << " | "
       << num(r["dt_stable_ms"], "%.4f") << " | " << num(r["dt_unstable_ms"], "%.4f") << " | "
       << num(r["stable_over_estimate"], "%.2f") << " | "
       << (r["confirmed"].get<bool>() ? "yes, " : "no, ") << r["confirmed_steps"] << " steps |\n";
  md << "\n";
}

void material_models(std::ostringstream& md, const json& mm) {
  md << "## Material models\n\nLamé's hollow sphere (a = 50, b = 100 mm, E = 60 kPa, 10 mmHg, one placement, voxels a "
        "quarter of the cube): the error of the mean displacement on the true spheres against the closed form with "
        "the nominal moduli.\n\n";
  md << "| model | ν | cube | device | inner | outer | iterations | s |\n|---|---|---|---|---|---|---|---|\n";
  for (const auto& r : mm["lame"])
    md << "| " << r["model"].get<std::string>() << " | " << num(r["poisson_ratio"], "%.2f") << " | "
       << num(r["cube_mm"], "%g") << " mm | " << r["device"].get<std::string>() << " | "
       << num(json(100 * r["rel_error_inner"].get<double>()), "%+.2f") << " % | "
       << num(json(100 * r["rel_error_outer"].get<double>()), "%+.2f") << " % | " << r["steps"] << " | "
       << num(r["wall_s"], "%.2f") << " |\n";
  if (!mm["real_ct"].empty()) {
    md << "\nThe real CT at each preset's cube size (all threads):\n\n| preset | model | solver | cube | nodes | s | "
          "iterations | rise mm | cavity ml | viscera back mm | viscera volume % | inverted | stop |\n"
          "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const auto& r : mm["real_ct"])
      md << "| " << r["preset"].get<std::string>() << " | " << r["model"].get<std::string>() << " | "
         << r["solver"].get<std::string>() << " | " << num(r["cube_mm"], "%g") << " mm | "
         << (r["nodes"].is_number() ? r["nodes"].dump() : "–") << " | "
         << num(r["wall_s"], "%.1f") << " | " << (r.contains("steps") ? r["steps"].dump() : "–") << " | "
         << (r.contains("anterior_rise_mm") ? num(r["anterior_rise_mm"], "%.1f") : "–") << " | "
         << (r.contains("cavity_volume_ml") ? num(r["cavity_volume_ml"], "%.0f") : "–") << " | "
         << (r.contains("viscera_posterior_motion_mm") ? num(r["viscera_posterior_motion_mm"], "%.1f") : "–") << " | "
         << (r.contains("viscera_volume_change_fraction")
                 ? num(json(100 * r["viscera_volume_change_fraction"].get<double>()), "%+.1f")
                 : "–")
         << " | " << (r.contains("inverted_tetrahedra") ? r["inverted_tetrahedra"].dump() : "–") << " | "
         << r["stop_reason"].get<std::string>() << " |\n";
  }
  const json& t = mm["throughput"];
  md << "\nFEM element updates per second (" << t["model"].get<std::string>() << ", " << t["case"].get<std::string>()
     << " phantom, " << t["nodes"] << " nodes):\n\n| device | evaluate /s | product /s | evaluate / triad | product / "
        "triad |\n|---|---|---|---|---|\n";
  for (const auto& r : t["rows"])
    md << "| " << r["device"].get<std::string>() << " | " << num(r["evaluate_element_updates_per_s"], "%.3g") << " | "
       << num(r["product_element_updates_per_s"], "%.3g") << " | "
       << (r.contains("evaluate_fraction_of_triad") ? num(r["evaluate_fraction_of_triad"], "%.2f") : "–") << " | "
       << (r.contains("product_fraction_of_triad") ? num(r["product_fraction_of_triad"], "%.2f") : "–") << " |\n";
  md << "\nPeer: " << t["peer"]["source"].get<std::string>() << " (" << t["peer"]["comparable"].get<std::string>()
     << ").\n\nWhich solver for which preset (" << mm["choice_rule"].get<std::string>() << "):\n\n";
  for (const auto& c : mm["choice"]) {
    md << "- **" << c["preset"].get<std::string>() << "**:";
    for (const auto& m : c["models"]) {
      md << " " << m["model"].get<std::string>() << ": ";
      if (m["fastest"].is_null()) md << "no converged real-CT row in this run";
      else
        md << m["fastest"]["solver"].get<std::string>() << " fastest (" << num(m["fastest"]["wall_s"], "%.1f")
           << " s), the preset takes " << m["preset_solver"].get<std::string>()
           << (m["follows"].get<bool>() ? " (follows)" : " (does not follow)");
      md << ";";
    }
    if (c.contains("model_pick")) {
      const json& p = c["model_pick"];
      md << " the model to pick (the fastest real-CT row within the adult figures: rise 25–60 mm, 1.5–4 L, viscera "
            "keeping their volume within 5 %): ";
      if (p["model"].is_null()) md << "none in this run";
      else
        md << p["model"].get<std::string>() << " with " << p["solver"].get<std::string>() << " ("
           << num(p["wall_s"], "%.1f") << " s); the default model, " << p["default_model"].get<std::string>()
           << (p["default_follows"].get<bool>() ? ", is it" : ", is not");
      md << ".";
    }
    md << "\n";
  }
  md << "\n";
}

}  // namespace

std::string speed_accuracy_svg(const json& sa) {
  static const std::map<std::string, std::string> colours = {
      {"static", "#1f77b4"}, {"explicit", "#ff7f0e"}, {"newmark", "#2ca02c"}, {"kitasaka2004", "#d62728"}};
  std::map<std::string, std::vector<std::pair<double, double>>> by_solver;
  std::vector<std::pair<double, double>> front;
  for (const auto& r : sa["runs"]) {
    if (r["rms_error_mm"].is_null()) continue;
    const double t = std::log10(r["wall_s"].get<double>()), e = r["rms_error_mm"].get<double>();
    by_solver[r["solver"].get<std::string>()].push_back({t, e});
    if (r["pareto"].get<bool>()) front.push_back({t, e});
  }
  std::vector<PlotSeries> series;
  for (auto& [name, pts] : by_solver) {
    std::sort(pts.begin(), pts.end());
    PlotSeries s;
    s.name = name;
    s.colour = colours.count(name) ? colours.at(name) : "#7f7f7f";
    s.markers = true;
    for (const auto& [t, e] : pts) {
      s.x.push_back(t);
      s.y.push_back(e);
    }
    series.push_back(s);
  }
  std::sort(front.begin(), front.end());
  PlotSeries f;
  f.name = "Pareto front";
  f.colour = "#000000";
  f.markers = true;
  for (const auto& [t, e] : front) {
    f.x.push_back(t);
    f.y.push_back(e);
  }
  series.push_back(f);
  PlotOptions o;
  o.title = "Wall time against displacement error (" + sa["phantom"].get<std::string>() + " phantom)";
  o.x_label = "log10 wall time (s)";
  o.y_label = "RMS displacement error (mm)";
  o.log_y = true;
  return line_plot_svg(series, o);
}

std::string bench_markdown(const json& doc, const std::string& plot_file_name) {
  std::ostringstream md;
  md << "# pneumo bench" << (doc["quick"].get<bool>() ? " (--quick)" : "") << "\n\n";
  md << "Written by `pneumo bench` (bench/suite). Every figure is a median over repetitions in one process, with "
        "its spread; none is a pass/fail. The machine is shared with other engineers' builds: read `other cores` "
        "(CPU other processes used while a figure was measured) before comparing numbers across runs.\n\n";
  machine(md, doc);
  throughput(md, doc);
  speed_accuracy(md, doc["speed_accuracy"], plot_file_name);
  stability(md, doc["stability"]);
  material_models(md, doc["material_models"]);
  md << "## Notes\n\n";
  for (const auto& n : doc["notes"]) md << "- " << n.get<std::string>() << "\n";
  return md.str();
}

void write_bench_markdown(const json& doc, const std::string& path) {
  std::filesystem::path svg(path);
  svg.replace_extension(".svg");
  write_text_file_atomic(svg.string(), speed_accuracy_svg(doc["speed_accuracy"]));
  write_text_file_atomic(path, bench_markdown(doc, svg.filename().string()));
}

}  // namespace pneumo::bench
