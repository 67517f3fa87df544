// saccade.mcap: recordings (record/mcap.h) read from Python. Reader yields each message decoded
// with its schema (record/ros_message.h): ROS 2 messages as dicts, sensor_msgs/Image's pixels
// as a numpy array (height x width [x channels]), other byte arrays as 1-D uint8 arrays, JSON
// messages as what their JSON holds.
#include <pybind11/stl.h>

#include <map>
#include <optional>
#include <set>

#include "python/internal_bindings.h"
#include "saccade/core/error.h"
#include "saccade/record/mcap.h"
#include "saccade/record/ros_message.h"

namespace saccade::python {
namespace {

using record::McapMessage;
using record::McapReader;

// A byte array as a numpy array of its own (the message's buffer is reused).
py::array Bytes(std::span<const uint8_t> bytes) {
  py::array_t<uint8_t> out(static_cast<py::ssize_t>(bytes.size()));
  std::memcpy(out.mutable_data(), bytes.data(), bytes.size());
  return out;
}

// An Image's pixels: height x width [x channels] of its encoding's type, rows re-packed when
// its step is wider (a raw Bayer mosaic: height x width, its pattern in the encoding); nullopt
// for an encoding without a fixed layout (then the bytes, 1-D).
std::optional<py::array> Pixels(const nlohmann::json& image, std::span<const uint8_t> data) {
  static const std::map<std::string, std::pair<int, std::string>> layouts = {
      {"rgb8", {3, "u1"}},          {"bgr8", {3, "u1"}},          {"rgba8", {4, "u1"}},
      {"bgra8", {4, "u1"}},         {"mono8", {1, "u1"}},         {"8UC1", {1, "u1"}},
      {"8UC3", {3, "u1"}},          {"mono16", {1, "<u2"}},       {"16UC1", {1, "<u2"}},
      {"32FC1", {1, "<f4"}},        {"bayer_rggb8", {1, "u1"}},   {"bayer_bggr8", {1, "u1"}},
      {"bayer_gbrg8", {1, "u1"}},   {"bayer_grbg8", {1, "u1"}},   {"bayer_rggb16", {1, "<u2"}},
      {"bayer_bggr16", {1, "<u2"}}, {"bayer_gbrg16", {1, "<u2"}}, {"bayer_grbg16", {1, "<u2"}},
  };
  const auto layout = layouts.find(image.value("encoding", ""));
  if (layout == layouts.end() || image.value("is_bigendian", 0) != 0) return std::nullopt;
  const auto height = image.value("height", 0u), width = image.value("width", 0u);
  const std::size_t step = image.value("step", 0u);
  const py::dtype dtype(layout->second.second);
  const std::size_t row = static_cast<std::size_t>(width) * layout->second.first * dtype.itemsize();
  if (step < row || data.size() < step * height) return std::nullopt;
  std::vector<py::ssize_t> shape = {height, width};
  if (layout->second.first > 1) shape.push_back(layout->second.first);
  py::array out(dtype, shape);
  auto* target = static_cast<uint8_t*>(out.mutable_data());
  for (uint32_t y = 0; y < height; ++y) std::memcpy(target + y * row, data.data() + y * step, row);
  return out;
}

// The decoded JSON as Python, each {"blob": i} replaced by its array.
py::object ToPython(const nlohmann::json& j, const std::vector<std::span<const uint8_t>>& blobs) {
  if (j.is_object() && j.size() == 1 && j.contains("blob") && j["blob"].is_number_unsigned()) {
    return Bytes(blobs.at(j["blob"].get<std::size_t>()));
  }
  if (j.is_object()) {
    py::dict d;
    for (const auto& [key, item] : j.items()) d[py::str(key)] = ToPython(item, blobs);
    return d;
  }
  if (j.is_array()) {
    py::list l;
    for (const auto& item : j) l.append(ToPython(item, blobs));
    return l;
  }
  return JsonToPython(j);
}

struct Message {
  std::string topic;
  std::string type;  // the schema's name, or "json"
  uint32_t sequence = 0;
  double log_time = 0.0, publish_time = 0.0;  // s
  py::object value;
};

// Reader.messages(): decodes as it goes; keeps the reader's schemas.
class MessageIterator {
 public:
  MessageIterator(std::shared_ptr<McapReader> reader, std::optional<std::set<std::string>> topics)
      : reader_(std::move(reader)), topics_(std::move(topics)), cursor_(reader_->Messages()) {}

  Message Next() {
    McapMessage m;
    while (true) {
      {
        py::gil_scoped_release release;  // reading and decompressing
        if (!cursor_->Next(&m)) throw py::stop_iteration();
      }
      const record::McapChannel& channel = reader_->channels().at(m.channel_id);
      if (topics_ && !topics_->count(channel.topic)) continue;
      Message out;
      out.topic = channel.topic;
      out.sequence = m.sequence;
      out.log_time = static_cast<double>(m.log_time) * 1e-9;
      out.publish_time = static_cast<double>(m.publish_time) * 1e-9;
      if (channel.message_encoding == "json") {
        out.type = "json";
        const std::string text(m.data.begin(), m.data.end());
        out.value = JsonToPython(nlohmann::json::parse(text, nullptr, false));
        return out;
      }
      const record::RosMessageDecoder* decoder = DecoderOf(channel);
      if (decoder == nullptr) {
        out.type = channel.message_encoding;
        out.value = Bytes(m.data);
        return out;
      }
      out.type = reader_->schemas().at(channel.schema_id).name;
      std::vector<std::span<const uint8_t>> blobs;
      const nlohmann::json value = decoder->Decode(m.data, &blobs);
      py::object python = ToPython(value, blobs);
      if (out.type == "sensor_msgs/msg/Image" && value.contains("data") &&
          value["data"].contains("blob")) {
        if (auto pixels = Pixels(value, blobs.at(value["data"]["blob"].get<std::size_t>()))) {
          python["data"] = *pixels;
        }
      }
      out.value = python;
      return out;
    }
  }

 private:
  const record::RosMessageDecoder* DecoderOf(const record::McapChannel& channel) {
    const auto schema = reader_->schemas().find(channel.schema_id);
    if (channel.message_encoding != "cdr" || schema == reader_->schemas().end() ||
        schema->second.encoding != "ros2msg") {
      return nullptr;
    }
    auto found = decoders_.find(schema->first);
    if (found == decoders_.end()) {
      found = decoders_
                  .emplace(schema->first,
                           record::RosMessageDecoder(schema->second.name, schema->second.data))
                  .first;
    }
    return &found->second;
  }

  std::shared_ptr<McapReader> reader_;
  std::optional<std::set<std::string>> topics_;
  std::unique_ptr<McapReader::Cursor> cursor_;
  std::map<uint16_t, record::RosMessageDecoder> decoders_;
};

}  // namespace

void BindRecord(py::module_& m) {
  py::class_<Message>(m, "Message", "One message of a recording, decoded")
      .def_readonly("topic", &Message::topic)
      .def_readonly("type", &Message::type,
                    "The ROS 2 type (\"sensor_msgs/msg/Image\"), or \"json\"")
      .def_readonly("sequence", &Message::sequence)
      .def_readonly("log_time", &Message::log_time, "s: when it was recorded (the run's clock)")
      .def_readonly("publish_time", &Message::publish_time, "s: its capture stamp")
      .def_readonly("value", &Message::value,
                    "The message as a dict; an Image's data is a numpy array (height x width "
                    "[x channels])")
      .def("__repr__", [](const Message& msg) {
        return "<saccade.mcap.Message " + msg.topic + " " + msg.type + " at " +
               std::to_string(msg.log_time) + " s>";
      });
  py::class_<MessageIterator>(m, "MessageIterator")
      .def("__iter__", [](MessageIterator& it) -> MessageIterator& { return it; })
      .def("__next__", &MessageIterator::Next);
  py::class_<McapReader, std::shared_ptr<McapReader>>(
      m, "Reader",
      "An MCAP recording (saccade's `--record FILE.mcap`, or rosbag2's): its topics and the "
      "messages decoded. A recording cut short (a killed run) is read up to its last complete "
      "chunk (`complete` is False). Raises saccade.FileError for a file that is not one.")
      .def(py::init([](const std::string& path) { return std::make_shared<McapReader>(path); }),
           "path"_a)
      .def_property_readonly(
          "topics",
          [](const McapReader& r) {
            std::map<std::string, std::string> topics;
            for (const auto& [id, c] : r.channels()) {
              const auto schema = r.schemas().find(c.schema_id);
              topics[c.topic] =
                  schema == r.schemas().end() ? c.message_encoding : schema->second.name;
            }
            return topics;
          },
          "Topic -> its ROS 2 type, or \"json\"")
      .def_property_readonly(
          "metadata",
          [](const McapReader& r) {
            std::map<std::string, std::map<std::string, std::string>> out;
            for (const record::McapMetadata& m : r.metadata()) out[m.name] = m.values;
            return out;
          },
          "The Metadata records: saccade's holds the head, scene and pipeline of the run")
      .def_property_readonly(
          "statistics",
          [](const McapReader& r) {
            const record::McapStatistics& s = r.statistics();
            py::dict counts;
            for (const auto& [id, n] : s.channel_message_counts) {
              counts[py::str(r.channels().at(id).topic)] = n;
            }
            return py::dict("messages"_a = s.message_count, "chunks"_a = s.chunk_count,
                            "start"_a = static_cast<double>(s.message_start_time) * 1e-9,
                            "end"_a = static_cast<double>(s.message_end_time) * 1e-9,
                            "counts"_a = counts);
          },
          "messages, chunks, start and end (s), counts by topic")
      .def_property_readonly(
          "complete", [](const McapReader& r) { return !r.recovered(); },
          "False for a recording cut short (read up to its last chunk)")
      .def_property_readonly("lost_bytes", &McapReader::lost_bytes)
      .def(
          "messages",
          [](std::shared_ptr<McapReader> r, std::optional<std::vector<std::string>> topics) {
            std::optional<std::set<std::string>> wanted;
            if (topics) wanted.emplace(topics->begin(), topics->end());
            return MessageIterator(std::move(r), std::move(wanted));
          },
          "topics"_a = py::none(),
          "Every message in file order (only those of `topics`, when given), decoded");
}

}  // namespace saccade::python
