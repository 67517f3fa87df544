// The DDS link between two processes (issue 16): stereo images (2 x 1024x768 RGB by default) at
// 30 Hz from a sender process to a receiver process on loopback, through saccade's writers and
// readers (sensor_msgs/Image with camera info and /tf) or through plain Cyclone DDS writing and
// taking the same sensor_msgs/Image (the baseline saccade's overhead is measured against).
// bench/dds_bench.sh runs both and ddsperf in the same run; figures in bench/baselines/.
//
//   dds_link_bench [--raw] [--seconds 10] [--rate 30] [--width 1024] [--height 768] [--domain 190]
//
// Latency: receive time minus the stamp the sender put in the header (CLOCK_REALTIME, one
// machine). Loss: images sent and not received. Per-message cost: the sender's time in write
// and the receiver's time in take (conversion included), CPU thread time.
#include <dds/dds.h>
#include <fmt/format.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <ctime>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "dds/internal_cyclone.h"
#include "saccade/core/image.h"
#include "saccade/dds/participant.h"
#include "saccade/dds/topics.h"
#include "saccade/geometry/image_camera.h"

namespace {

using namespace saccade;

struct Options {
  bool raw = false;
  double seconds = 10;
  double rate = 30;
  int width = 1024;
  int height = 768;
  int domain = 190;
};

double Now() {
  timespec ts;
  clock_gettime(CLOCK_REALTIME, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

double ThreadCpu() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

double Percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(p * static_cast<double>(v.size() - 1) + 0.5)];
}

const char* kTopics[2] = {"/bench/left/image_raw", "/bench/right/image_raw"};

std::shared_ptr<Image> MakeImage(const Options& o, const std::string& camera) {
  auto image = std::make_shared<Image>(o.width, o.height, PixelFormat::kRgb8);
  for (std::size_t i = 0; i < image->size_bytes(); ++i)
    image->data()[i] = static_cast<uint8_t>(i * 7);
  image->metadata().camera = camera;
  geometry::SetCameraModel(image->metadata(),
                           std::make_shared<const geometry::CameraModel>(geometry::Intrinsics(
                               o.width, o.height, 800, 800, o.width / 2.0, o.height / 2.0)));
  geometry::SetCameraPose(image->metadata(), geometry::Pose::Identity());
  return image;
}

// ---- plain Cyclone DDS ------------------------------------------------------------------

dds_entity_t RawEndpoint(dds_entity_t participant, const char* ros_topic, bool writer) {
  const std::string name = std::string("rt") + ros_topic;
  const dds_entity_t topic = dds_create_topic(participant, &sensor_msgs_msg_dds__Image__desc,
                                              name.c_str(), nullptr, nullptr);
  dds_qos_t* qos = dds_create_qos();
  dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 2);
  const dds_entity_t e = writer ? dds_create_writer(participant, topic, qos, nullptr)
                                : dds_create_reader(participant, topic, qos, nullptr);
  dds_delete_qos(qos);
  return e;
}

int Send(const Options& o) {
  const auto left = MakeImage(o, "left"), right = MakeImage(o, "right");
  std::vector<double> write_cpu;
  int64_t sent = 0;
  const auto period = std::chrono::duration<double>(1.0 / o.rate);
  std::shared_ptr<dds::Participant> participant;
  std::unique_ptr<dds::Writer> writers[2];
  dds_entity_t raw_participant = 0, raw_writers[2] = {0, 0};
  if (o.raw) {
    raw_participant =
        dds_create_participant(static_cast<dds_domainid_t>(o.domain), nullptr, nullptr);
    for (int i = 0; i < 2; ++i) raw_writers[i] = RawEndpoint(raw_participant, kTopics[i], true);
  } else {
    dds::DomainOptions domain;
    domain.domain_id = o.domain;
    participant = dds::Participant::Create(domain);
    for (int i = 0; i < 2; ++i) {
      dds::TopicOptions topic;
      topic.topic = kTopics[i];
      topic.qos = dds::Qos::Images();
      writers[i] = dds::Writer::Create(participant, "runtime.image", topic);
    }
  }
  // Wait for the receiver's two readers.
  for (int i = 0; i < 2; ++i) {
    for (int t = 0; t < 2000; ++t) {
      dds_publication_matched_status_t status{};
      int matched = 0;
      if (o.raw) {
        dds_get_publication_matched_status(raw_writers[i], &status);
        matched = static_cast<int>(status.current_count);
      } else {
        matched = writers[i]->matched();
      }
      if (matched > 0) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  auto next = std::chrono::steady_clock::now();
  const int64_t frames = static_cast<int64_t>(o.seconds * o.rate);
  for (int64_t f = 0; f < frames; ++f) {
    std::this_thread::sleep_until(next);
    next += std::chrono::duration_cast<std::chrono::steady_clock::duration>(period);
    for (int i = 0; i < 2; ++i) {
      const std::shared_ptr<Image>& image = i == 0 ? left : right;
      image->metadata().time = Now();
      const double cpu = ThreadCpu();
      if (o.raw) {
        sensor_msgs_msg_dds__Image_ msg{};
        const auto ns = static_cast<int64_t>(image->metadata().time * 1e9);
        msg.header.stamp = {static_cast<int32_t>(ns / 1000000000),
                            static_cast<uint32_t>(ns % 1000000000)};
        msg.header.frame_id = const_cast<char*>("left_optical");
        msg.height = static_cast<uint32_t>(o.height);
        msg.width = static_cast<uint32_t>(o.width);
        msg.encoding = const_cast<char*>("rgb8");
        msg.step = static_cast<uint32_t>(image->stride());
        msg.data = {static_cast<uint32_t>(image->size_bytes()),
                    static_cast<uint32_t>(image->size_bytes()), image->data(), false};
        dds_write(raw_writers[i], &msg);
      } else {
        writers[i]->Write(runtime::ImageMessage{image});
      }
      write_cpu.push_back(ThreadCpu() - cpu);
      ++sent;
    }
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  fmt::print("sender   {}: {} images sent, write {:.3f} ms CPU per image (mean)\n",
             o.raw ? "plain Cyclone" : "saccade", sent,
             1e3 * (write_cpu.empty() ? 0 : [&] {
               double s = 0;
               for (double v : write_cpu) s += v;
               return s / static_cast<double>(write_cpu.size());
             }()));
  if (raw_participant) dds_delete(raw_participant);
  return 0;
}

int Receive(const Options& o) {
  std::vector<double> latency, take_cpu;
  std::shared_ptr<dds::Participant> participant;
  std::unique_ptr<dds::Reader> readers[2];
  dds_entity_t raw_participant = 0, raw_readers[2] = {0, 0};
  if (o.raw) {
    raw_participant =
        dds_create_participant(static_cast<dds_domainid_t>(o.domain), nullptr, nullptr);
    for (int i = 0; i < 2; ++i) raw_readers[i] = RawEndpoint(raw_participant, kTopics[i], false);
  } else {
    dds::DomainOptions domain;
    domain.domain_id = o.domain;
    participant = dds::Participant::Create(domain);
    for (int i = 0; i < 2; ++i) {
      dds::TopicOptions topic;
      topic.topic = kTopics[i];
      topic.qos = dds::Qos::Images();
      readers[i] = dds::Reader::Create(participant, "runtime.image", topic);
    }
  }
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(o.seconds + 8);
  const int64_t expected = 2 * static_cast<int64_t>(o.seconds * o.rate);
  int64_t received = 0;
  while (std::chrono::steady_clock::now() < end && received < expected) {
    bool got = false;
    for (int i = 0; i < 2; ++i) {
      const double cpu = ThreadCpu();
      if (o.raw) {
        void* samples[4] = {nullptr};
        dds_sample_info_t infos[4];
        const dds_return_t n = dds_take(raw_readers[i], samples, infos, 4, 4);
        for (dds_return_t k = 0; k < n; ++k) {
          if (!infos[k].valid_data) continue;
          const auto* msg = static_cast<const sensor_msgs_msg_dds__Image_*>(samples[k]);
          latency.push_back(Now() - (msg->header.stamp.sec + 1e-9 * msg->header.stamp.nanosec));
          ++received;
          got = true;
        }
        if (n > 0) {
          dds_return_loan(raw_readers[i], samples, n);
          take_cpu.push_back(ThreadCpu() - cpu);
        }
      } else if (auto m = readers[i]->Take<runtime::ImageMessage>(0.0)) {
        latency.push_back(Now() - m->image->metadata().time);
        take_cpu.push_back(ThreadCpu() - cpu);
        ++received;
        got = true;
      }
    }
    if (!got) std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
  double cpu_mean = 0;
  for (double v : take_cpu) cpu_mean += v / static_cast<double>(take_cpu.size());
  fmt::print(
      "receiver {}: {} of {} images ({} lost), latency p50 {:.2f} ms, p95 {:.2f} ms, max {:.2f} "
      "ms; take {:.3f} ms CPU per image (mean)\n",
      o.raw ? "plain Cyclone" : "saccade", received, expected, expected - received,
      1e3 * Percentile(latency, 0.5), 1e3 * Percentile(latency, 0.95),
      1e3 * Percentile(latency, 1.0), 1e3 * cpu_mean);
  if (raw_participant) dds_delete(raw_participant);
  return received == expected ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const auto Next = [&]() -> double {
      if (i + 1 >= argc) {
        fmt::print(stderr, "dds_link_bench: {} needs a value\n", a);
        std::exit(2);
      }
      return std::stod(argv[++i]);
    };
    if (a == "--raw")
      o.raw = true;
    else if (a == "--seconds")
      o.seconds = Next();
    else if (a == "--rate")
      o.rate = Next();
    else if (a == "--width")
      o.width = static_cast<int>(Next());
    else if (a == "--height")
      o.height = static_cast<int>(Next());
    else if (a == "--domain")
      o.domain = static_cast<int>(Next());
    else {
      fmt::print(stderr,
                 "usage: dds_link_bench [--raw] [--seconds S] [--rate HZ] [--width W] "
                 "[--height H] [--domain D]\n");
      return 2;
    }
  }
  // Loopback only, as every benchmark (config/dds/loopback.xml).
  setenv("CYCLONEDDS_URI", "file://" SACCADE_SOURCE_DIR "/config/dds/loopback.xml", 0);
  std::fflush(stdout);
  const pid_t child = fork();  // before any DDS call: Cyclone's threads do not survive a fork
  if (child == 0) return Receive(o);
  const int sent = Send(o);
  int status = 0;
  waitpid(child, &status, 0);
  return sent != 0 ? sent : (WIFEXITED(status) ? WEXITSTATUS(status) : 1);
}
