// Readers over still images: an image list file and a single image.

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <opencv2/core/persistence.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include "internal_frame_reader.h"
#include "saccade/hw/hw_error.h"

namespace saccade::hw::internal {
namespace {

namespace fs = std::filesystem;

/// One image of a list, and how messages name it.
struct Entry {
  fs::path path;
  /// "<list>:<line>: entry '<as written>' (<path>)", "<list>: imagelist[<i>]: entry ..." or
  /// "image <path>".
  std::string label;
};

Entry ListEntry(const fs::path& list, const std::string& where, const std::string& text) {
  const fs::path path = list.parent_path() / text;
  return {path, where + ": entry '" + text + "' (" + path.string() + ")"};
}

class ImageListReader final : public FrameReader {
 public:
  ImageListReader(std::string device, std::vector<Entry> entries)
      : device_(std::move(device)), entries_(std::move(entries)) {}

  bool live() const override { return false; }

  bool Latch() override {
    if (next_ >= entries_.size()) return false;
    current_ = next_++;
    return true;
  }

  cv::Mat Retrieve() override {
    const Entry& entry = entries_[current_];
    // As stored (gray stays gray, 16-bit stays 16-bit), like CAP_IMAGES.
    cv::Mat image = CallOpenCv(device_, entry.label, [&] {
      return cv::imread(entry.path.string(), cv::IMREAD_UNCHANGED);
    });
    if (image.empty())
      throw HardwareError(device_, entry.label + ": cannot be decoded as an image");
    return image;
  }

  void Rewind() override { next_ = 0; }

 private:
  std::string device_;
  std::vector<Entry> entries_;
  size_t next_ = 0;
  size_t current_ = 0;
};

std::string LowerCase(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

std::string_view Trim(std::string_view s) {
  const size_t begin = s.find_first_not_of(" \t\r\n");
  if (begin == std::string_view::npos) return {};
  const size_t end = s.find_last_not_of(" \t\r\n");
  return s.substr(begin, end - begin + 1);
}

// FileStorage by extension (.xml, .yml, .yaml, .json, also gzipped) or by its first bytes.
bool IsFileStorage(const fs::path& path, const std::string& head) {
  std::string name = LowerCase(path.filename().string());
  if (name.ends_with(".gz")) name.resize(name.size() - 3);
  for (const char* extension : {".xml", ".yml", ".yaml", ".json"}) {
    if (name.ends_with(extension)) return true;
  }
  const std::string_view start = Trim(head);
  return start.starts_with("<?xml") || start.starts_with("<opencv_storage") ||
         start.starts_with("%YAML");
}

std::vector<Entry> ReadFileStorageList(const std::string& device, const fs::path& list) {
  const std::string file = list.string();
  std::vector<Entry> entries;
  CallOpenCv(device, "image list " + file, [&] {
    cv::FileStorage storage(file, cv::FileStorage::READ);
    if (!storage.isOpened()) {
      throw HardwareError(device, "image list " + file + ": cannot be read as OpenCV FileStorage");
    }
    const cv::FileNode node = storage["imagelist"];
    if (node.empty() || node.isNone()) {
      throw HardwareError(device, "image list " + file +
                                      ": missing key imagelist; expected a sequence of image "
                                      "file names (as OpenCV's stereo_calib.xml)");
    }
    if (!node.isSeq()) {
      throw HardwareError(device, "image list " + file +
                                      ": imagelist is not a sequence; expected image file names");
    }
    int index = 0;
    for (const cv::FileNode& item : node) {
      const std::string where = file + ": imagelist[" + std::to_string(index) + "]";
      if (!item.isString()) {
        throw HardwareError(device, where + ": expected a file name (a string)");
      }
      entries.push_back(ListEntry(list, where, item.string()));
      ++index;
    }
    return 0;
  });
  return entries;
}

std::vector<Entry> ReadTextList(const fs::path& list, const std::string& text) {
  std::vector<Entry> entries;
  size_t start = 0;
  int line = 0;
  while (start < text.size()) {
    size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    ++line;
    const std::string_view item = Trim(std::string_view(text).substr(start, end - start));
    start = end + 1;
    if (item.empty() || item.starts_with('#')) continue;
    entries.push_back(
        ListEntry(list, list.string() + ":" + std::to_string(line), std::string(item)));
  }
  return entries;
}

// Every entry must be an image file OpenCV can read: found now rather than frames later.
void CheckEntries(const std::string& device, const std::vector<Entry>& entries) {
  for (const Entry& entry : entries) {
    const std::string& name = entry.label;
    std::error_code ec;
    const fs::file_status status = fs::status(entry.path, ec);
    if (!fs::exists(status)) throw HardwareError(device, name + ": file not found");
    if (!fs::is_regular_file(status)) throw HardwareError(device, name + ": not a file");
    const bool readable =
        CallOpenCv(device, name, [&] { return cv::haveImageReader(entry.path.string()); });
    if (!readable) {
      throw HardwareError(device, name + ": not an image OpenCV can read");
    }
  }
}

}  // namespace

std::unique_ptr<FrameReader> OpenImageList(const std::string& device, const fs::path& list) {
  const std::string file = list.string();
  std::error_code ec;
  const fs::file_status status = fs::status(list, ec);
  if (!fs::exists(status)) throw HardwareError(device, "image list " + file + ": file not found");
  if (fs::is_directory(status)) {
    throw HardwareError(device, "image list " + file + ": is a folder, expected a list file");
  }
  std::ifstream in(list, std::ios::binary);
  if (!in) throw HardwareError(device, "image list " + file + ": cannot be opened for reading");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::vector<Entry> entries = IsFileStorage(list, text.substr(0, 64))
                                         ? ReadFileStorageList(device, list)
                                         : ReadTextList(list, text);
  if (entries.empty()) {
    throw HardwareError(device, "image list " + file + ": empty list, expected image file names");
  }
  CheckEntries(device, entries);
  return std::make_unique<ImageListReader>(device, entries);
}

std::unique_ptr<FrameReader> OpenStillImage(const std::string& device, const fs::path& path) {
  std::vector<Entry> entries = {{path, "image " + path.string()}};
  CheckEntries(device, entries);
  return std::make_unique<ImageListReader>(device, std::move(entries));
}

}  // namespace saccade::hw::internal
