#include "io/dicom_io.h"

#include <gdcmImage.h>
#include <gdcmImageReader.h>
#include <gdcmPixelFormat.h>
#include <gdcmScanner.h>
#include <gdcmTag.h>

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <vector>

#include "core/error.h"
#include "core/log.h"
#include "io/volume_io.h"

namespace pneumo {
namespace {

const gdcm::Tag kModality(0x0008, 0x0060), kSeriesUid(0x0020, 0x000e), kPosition(0x0020, 0x0032),
    kOrientation(0x0020, 0x0037), kRows(0x0028, 0x0010), kColumns(0x0028, 0x0011), kPixelSpacing(0x0028, 0x0030),
    kFrames(0x0028, 0x0008), kRescaleIntercept(0x0028, 0x1052), kRescaleSlope(0x0028, 0x1053);

// The most HU a CT holds is a few ten thousand (metal on an extended scale); a rescale that maps
// stored values beyond this is a wrong tag, not a body (1e300 gave infinite voxels).
constexpr double kMostAbsHu = 1e5;

std::string trimmed(const char* s) {
  std::string t = s ? s : "";
  while (!t.empty() && (t.back() == ' ' || t.back() == '\0')) t.pop_back();
  while (!t.empty() && t.front() == ' ') t.erase(t.begin());
  return t;
}

/// A decimal-string value of `n` numbers separated by backslashes (DICOM PS3.5 §6.2, DS).
std::vector<double> numbers(const std::string& dir, const std::string& file, const char* value, std::size_t n,
                            const char* what) {
  std::vector<double> out;
  std::stringstream ss(trimmed(value));
  std::string item;
  bool ok = true;
  while (ok && std::getline(ss, item, '\\')) {
    try {
      std::size_t used = 0;
      out.push_back(std::stod(item, &used));
      ok = trimmed(item.substr(used).c_str()).empty();
    } catch (const std::exception&) {
      ok = false;
    }
  }
  if (!ok) out.clear();
  if (out.size() != n || !std::all_of(out.begin(), out.end(), [](double v) { return std::isfinite(v); }))
    throw file_error(dir, std::string(what) + " of " + file + " is \"" + trimmed(value) + "\", not " +
                              std::to_string(n) + " numbers");
  return out;
}

struct Slice {
  std::string file;
  Vec3 position_lps;
  double along_normal = 0.0;
};

std::string name_of(const std::string& path) { return std::filesystem::path(path).filename().string(); }

/// HU = slope × stored + intercept (PS3.3 C.11.1.1.2), from the tags as the file holds them: GDCM's
/// Image::GetSlope() turns a slope of 0 into 1, which would read a wrong file as a plausible CT.
struct Rescale {
  double slope = 1.0, intercept = 0.0;
};

Rescale rescale_of(const std::string& dir, const std::string& file, const char* slope, const char* intercept) {
  Rescale r;
  if (slope && !trimmed(slope).empty())
    r.slope = numbers(dir, file, slope, 1, "Rescale Slope (0028,1053)")[0];
  if (intercept && !trimmed(intercept).empty())
    r.intercept = numbers(dir, file, intercept, 1, "Rescale Intercept (0028,1052)")[0];
  if (r.slope == 0.0)
    throw file_error(dir, file + ": Rescale Slope (0028,1053) is 0, which maps every stored value to one HU: fix the "
                                "tag (CT exports write 1)");
  return r;
}

/// Refuses a rescale that takes the slice's stored values [lo, hi] outside what HU can be.
void check_rescaled_range(const std::string& dir, const std::string& file, const Rescale& r, double lo, double hi) {
  const double a = r.slope * lo + r.intercept, b = r.slope * hi + r.intercept;
  if (std::isfinite(a) && std::isfinite(b) && std::abs(a) <= kMostAbsHu && std::abs(b) <= kMostAbsHu) return;
  std::ostringstream os;
  os << file << ": Rescale Slope (0028,1053) " << r.slope << " and Intercept (0028,1052) " << r.intercept
     << " map its stored values " << lo << " .. " << hi << " to " << std::min(a, b) << " .. " << std::max(a, b)
     << " HU, beyond the ±" << kMostAbsHu << " HU a CT holds: fix the tags";
  throw file_error(dir, os.str());
}

/// Whether a file starts as a DICOM file does, from its first 132 bytes: a DICOM file (Part 10) has
/// "DICM" after a 128-byte preamble; an older one without it (ACR-NEMA) starts with a data set whose
/// first group is 0008, little-endian. Everything else is passed over before GDCM sees it: Debian's
/// GDCM 3.0 stops the process on an assert() while scanning some short files that are neither (a
/// fuzzer's 9 bytes, 02 00 2b 28 02 00 2b 01 02).
bool starts_as_dicom(const std::string& path) {
  unsigned char head[132] = {};
  InputFile in(path, "the slice");
  std::size_t got = 0;
  while (got < sizeof head) {
    const ssize_t n = ::read(in.fd(), head + got, sizeof head - got);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    got += std::size_t(n);
  }
  if (got == sizeof head && std::memcmp(head + 128, "DICM", 4) == 0) return true;
  return got >= 8 && head[0] == 0x08 && head[1] == 0x00;
}

}  // namespace

SeriesFolder classify_series_entries(const std::string& dir, std::vector<FolderEntry> entries) {
  std::sort(entries.begin(), entries.end(), [](const FolderEntry& a, const FolderEntry& b) { return a.name < b.name; });
  SeriesFolder out;
  for (const FolderEntry& e : entries) {
    const std::string path = (std::filesystem::path(dir) / e.name).string();
    if (e.probe.kind == FileKind::Regular) out.files.push_back(path);
    else if (e.probe.kind == FileKind::Folder) out.skipped_folders.push_back(e.name);
    else
      throw file_error(dir, e.name + " " + file_kind_problem(e.probe, "move it out of the folder (every file in "
                                                                            "a series folder is read)"));
  }
  return out;
}

SeriesFolder list_series_folder(const std::string& dir) {
  std::vector<FolderEntry> entries;
  std::error_code ec;
  std::filesystem::directory_iterator it(dir, ec), end;
  for (; !ec && it != end; it.increment(ec)) {
    const std::string path = it->path().string();
    FileProbe probe = probe_file(path);
    // GDCM's scan would pass over a file it cannot open as one that is not DICOM: a slice lost.
    if (probe.kind == FileKind::Regular && ::access(path.c_str(), R_OK) != 0) probe = {FileKind::Unreadable, errno, {}, 0};
    entries.push_back({it->path().filename().string(), probe});
  }
  if (ec) throw file_error(dir, "cannot list the folder: " + ec.message());
  return classify_series_entries(dir, std::move(entries));
}

bool is_dicom_series_folder(const std::string& path) {
  std::error_code ec;
  return std::filesystem::is_directory(path, ec);
}

Volume read_dicom_series(const std::string& dir) {
  if (!is_dicom_series_folder(dir)) throw file_error(dir, "not a folder (a DICOM series is read from its folder)");
  const SeriesFolder listing = list_series_folder(dir);
  for (const std::string& folder : listing.skipped_folders)
    log::info(dir + ": skipped the sub-folder " + folder + " (a series is read from its own folder only)");
  gdcm::Scanner scanner;
  for (const gdcm::Tag& t : {kModality, kSeriesUid, kPosition, kOrientation, kRows, kColumns, kPixelSpacing, kFrames,
                             kRescaleIntercept, kRescaleSlope})
    scanner.AddTag(t);
  std::vector<std::string> candidates;
  for (const std::string& f : listing.files)
    if (starts_as_dicom(f)) candidates.push_back(f);
  if (!scanner.Scan(candidates)) throw file_error(dir, "cannot scan the folder's files for DICOM");

  std::vector<std::string> files;
  std::set<std::string> series;
  for (const std::string& f : candidates) {
    if (!scanner.IsKey(f.c_str())) continue;   // not DICOM: a DICOMDIR's neighbours, notes, thumbnails
    files.push_back(f);
    series.insert(trimmed(scanner.GetValue(f.c_str(), kSeriesUid)));
  }
  if (files.empty()) throw file_error(dir, "holds no DICOM file (give the folder of one CT series)");
  if (series.size() > 1)
    throw file_error(dir, "holds " + std::to_string(series.size()) +
                              " series (Series Instance UID): give the folder of one CT series");

  // The geometry every slice must share: the first file's, checked against each other's.
  const std::string& first = files.front();
  auto value = [&](const std::string& f, const gdcm::Tag& t) { return scanner.GetValue(f.c_str(), t); };
  std::vector<Slice> slices;
  std::vector<double> orientation, spacing;
  std::string rows, columns;
  for (const std::string& f : files) {
    const std::string modality = trimmed(value(f, kModality));
    if (modality != "CT")
      throw file_error(dir, name_of(f) + " is modality \"" + modality + "\": pneumo needs a CT series (HU)");
    if (!trimmed(value(f, kFrames)).empty() && trimmed(value(f, kFrames)) != "1")
      throw file_error(dir, name_of(f) + " is a multi-frame image (" + trimmed(value(f, kFrames)) +
                                " frames): export the series as one file per slice");
    if (!value(f, kPosition) || !value(f, kOrientation) || !value(f, kPixelSpacing))
      throw file_error(dir, name_of(f) + " lacks Image Position, Image Orientation or Pixel Spacing (Patient)");
    const std::vector<double> o = numbers(dir, name_of(f), value(f, kOrientation), 6, "Image Orientation (Patient)");
    const std::vector<double> s = numbers(dir, name_of(f), value(f, kPixelSpacing), 2, "Pixel Spacing");
    const std::vector<double> p = numbers(dir, name_of(f), value(f, kPosition), 3, "Image Position (Patient)");
    if (f == first) {
      orientation = o, spacing = s, rows = trimmed(value(f, kRows)), columns = trimmed(value(f, kColumns));
    } else {
      for (int c = 0; c < 6; ++c)
        if (std::abs(o[std::size_t(c)] - orientation[std::size_t(c)]) > 1e-4)
          throw file_error(dir, name_of(f) + " has another orientation than " + name_of(first) +
                                    ": not one volume");
      for (int c = 0; c < 2; ++c)
        if (std::abs(s[std::size_t(c)] - spacing[std::size_t(c)]) > 1e-4 * spacing[std::size_t(c)])
          throw file_error(dir, name_of(f) + " has another pixel spacing than " + name_of(first) + ": not one volume");
      if (trimmed(value(f, kRows)) != rows || trimmed(value(f, kColumns)) != columns)
        throw file_error(dir, name_of(f) + " has another image size than " + name_of(first) + ": not one volume");
    }
    slices.push_back({f, Vec3(p[0], p[1], p[2]), 0.0});
  }
  if (slices.size() < 2) throw file_error(dir, "holds one slice: a volume needs at least two");
  if (!(spacing[0] > 0.0 && spacing[1] > 0.0)) throw file_error(dir, "Pixel Spacing is not positive");

  // The frame (PS3.3 C.7.6.2.1.1): the first three of the orientation are the direction of a row,
  // along which the column index (pneumo's i) grows; the last three the direction down a column (j).
  Vec3 along_row(orientation[0], orientation[1], orientation[2]), along_column(orientation[3], orientation[4],
                                                                                orientation[5]);
  if (std::abs(along_row.norm() - 1.0) > 1e-3 || std::abs(along_column.norm() - 1.0) > 1e-3 ||
      std::abs(along_row.dot(along_column)) > 1e-3)
    throw file_error(dir, "Image Orientation (Patient) is not two orthonormal directions");
  along_row.normalize();
  along_column = (along_column - along_row.dot(along_column) * along_row).normalized();
  const Vec3 normal = along_row.cross(along_column);
  for (Slice& s : slices) s.along_normal = s.position_lps.dot(normal);
  std::sort(slices.begin(), slices.end(), [](const Slice& a, const Slice& b) { return a.along_normal < b.along_normal; });

  // Even gaps along the normal, and positions on the normal (no gantry tilt, no shear).
  const std::size_t n_slices = slices.size();
  const double gap = (slices.back().along_normal - slices.front().along_normal) / double(n_slices - 1);
  for (std::size_t s = 1; s < n_slices; ++s) {
    const double step = slices[s].along_normal - slices[s - 1].along_normal;
    if (step < 1e-3)
      throw file_error(dir, name_of(slices[s - 1].file) + " and " + name_of(slices[s].file) +
                                " lie at one position: two acquisitions in one series?");
    if (std::abs(step - gap) > 0.01 * gap + 1e-3) {
      std::ostringstream os;
      os << "slices are not evenly spaced: " << step << " mm between " << name_of(slices[s - 1].file) << " and "
         << name_of(slices[s].file) << " where the series averages " << gap << " mm (a missing slice?)";
      throw file_error(dir, os.str());
    }
    const Vec3 offset = slices[s].position_lps - slices[s - 1].position_lps;
    if ((offset - step * normal).norm() > 0.01 * gap + 1e-3)
      throw file_error(dir, "slice positions are not along the slice normal (a tilted gantry): resample the series "
                            "to a tilt-free one first");
  }

  // pneumo's grid in world RAS: DICOM's LPS with x and y turned.
  const Mat3 lps_to_ras = Vec3(-1.0, -1.0, 1.0).asDiagonal();
  Geometry g;
  const auto count = [&](const std::string& text, const char* what) {
    try {
      std::size_t used = 0;
      const long long n = std::stoll(text, &used);
      if (used == text.size() && n > 0) return int64_t(n);
    } catch (const std::exception&) {
    }
    throw file_error(dir, std::string(what) + " is \"" + text + "\", not a positive number");
  };
  g.dims = {count(columns, "Columns"), count(rows, "Rows"), int64_t(n_slices)};
  g.spacing_mm = Vec3(spacing[1], spacing[0], gap);   // Pixel Spacing is (between rows, between columns)
  g.origin_mm = lps_to_ras * slices.front().position_lps;
  g.direction.col(0) = lps_to_ras * along_row;
  g.direction.col(1) = lps_to_ras * along_column;
  g.direction.col(2) = lps_to_ras * normal;
  g.validate(dir);
  require_volume_memory(dir, g, VoxelType::Float32);

  Volume v(g, VoxelType::Float32);
  float* out = v.data<float>();
  const std::size_t per_slice = std::size_t(g.dims[0] * g.dims[1]);
  std::vector<char> buffer;
  for (std::size_t s = 0; s < n_slices; ++s) {
    gdcm::ImageReader reader;
    reader.SetFileName(slices[s].file.c_str());
    if (!reader.Read()) throw file_error(dir, name_of(slices[s].file) + ": GDCM cannot read its image");
    const gdcm::Image& image = reader.GetImage();
    const gdcm::PixelFormat& pf = image.GetPixelFormat();
    if (pf.GetSamplesPerPixel() != 1 ||
        image.GetPhotometricInterpretation() != gdcm::PhotometricInterpretation::MONOCHROME2)
      throw file_error(dir, name_of(slices[s].file) + " is not a greyscale (MONOCHROME2) image");
    if (image.GetDimension(0) != unsigned(g.dims[0]) || image.GetDimension(1) != unsigned(g.dims[1]))
      throw file_error(dir, name_of(slices[s].file) + ": its pixel data is not Rows × Columns");
    // Uncompressed pixel data shorter than Rows × Columns is refused before the slice's buffer is
    // allocated from what Rows and Columns promise (compressed data is checked by decoding it).
    const gdcm::ByteValue* stored = image.GetDataElement().GetByteValue();
    if (stored && stored->GetLength() < image.GetBufferLength())
      throw file_error(dir, name_of(slices[s].file) + ": its pixel data holds " + std::to_string(stored->GetLength()) +
                                " bytes where Rows × Columns need " + std::to_string(image.GetBufferLength()));
    buffer.resize(image.GetBufferLength());
    if (!image.GetBuffer(buffer.data())) throw file_error(dir, name_of(slices[s].file) + ": cannot decode its pixels");
    const Rescale rescale = rescale_of(dir, name_of(slices[s].file), value(slices[s].file, kRescaleSlope),
                                       value(slices[s].file, kRescaleIntercept));
    float* dst = out + s * per_slice;
    auto convert = [&](auto sample) {
      using T = decltype(sample);
      if (buffer.size() < per_slice * sizeof(T))
        throw file_error(dir, name_of(slices[s].file) + ": its pixel data is shorter than Rows × Columns");
      T lo = std::numeric_limits<T>::max(), hi = std::numeric_limits<T>::lowest();
      for (std::size_t n = 0; n < per_slice; ++n) {
        T raw;
        std::memcpy(&raw, buffer.data() + n * sizeof(T), sizeof(T));
        lo = std::min(lo, raw), hi = std::max(hi, raw);
      }
      check_rescaled_range(dir, name_of(slices[s].file), rescale, double(lo), double(hi));
      for (std::size_t n = 0; n < per_slice; ++n) {
        T raw;
        std::memcpy(&raw, buffer.data() + n * sizeof(T), sizeof(T));
        dst[n] = float(rescale.slope * double(raw) + rescale.intercept);
      }
    };
    switch (pf.GetScalarType()) {
      case gdcm::PixelFormat::UINT8: convert(uint8_t{}); break;
      case gdcm::PixelFormat::INT8: convert(int8_t{}); break;
      case gdcm::PixelFormat::UINT16: convert(uint16_t{}); break;
      case gdcm::PixelFormat::INT16: convert(int16_t{}); break;
      case gdcm::PixelFormat::UINT32: convert(uint32_t{}); break;
      case gdcm::PixelFormat::INT32: convert(int32_t{}); break;
      default:
        throw file_error(dir, name_of(slices[s].file) + ": pixel type " + pf.GetScalarTypeAsString() +
                                  " is not an integer CT's");
    }
  }
  return v;
}

}  // namespace pneumo
