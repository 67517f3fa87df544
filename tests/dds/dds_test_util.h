#pragma once
// Helpers of the DDS tests: loopback pinning, a plain Cyclone DDS reader and writer of the
// tests' own ROS 2 types (tests/dds/idl/ros2_reference.idl, ref_* symbols), raw CDR bytes, and
// (reference_serializer.h) Foxglove's independent serializer under Node.
#include <dds/dds.h>
#include <dds/ddsi/ddsi_serdata.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include "reference_serializer.h"
#include "ros2_reference.h"
#include "saccade/dds/participant.h"
#include "saccade/dds/topics.h"

namespace saccade::dds::testing {

/// Every DDS test stays on the loopback interface (ctest sets CYCLONEDDS_URI too; this covers
/// running the test program by hand).
inline void PinLoopback() {
  setenv("CYCLONEDDS_URI", "file://" SACCADE_SOURCE_DIR "/config/dds/loopback.xml", 0);
}

/// Options of domain `id` with saccade's loopback configuration.
inline DomainOptions Domain(int id, const std::string& config = "loopback") {
  DomainOptions options;
  options.domain_id = id;
  options.config = config;
  return options;
}

/// A topic's options.
inline TopicOptions Topic(const std::string& topic, const Qos& qos = Qos::Default(),
                          double frame_period_s = 0.0) {
  TopicOptions options;
  options.topic = topic;
  options.qos = qos;
  options.frame_period_s = frame_period_s;
  return options;
}

/// A plain Cyclone DDS participant, reader or writer; deleted with the object.
class Raw {
 public:
  explicit Raw(dds_entity_t handle) : handle_(handle) {
    if (handle_ < 0) ADD_FAILURE() << "Cyclone: " << dds_strretcode(handle_);
  }
  ~Raw() {
    if (handle_ > 0) dds_delete(handle_);
  }
  Raw(const Raw&) = delete;
  Raw& operator=(const Raw&) = delete;
  dds_entity_t get() const { return handle_; }

 private:
  dds_entity_t handle_;
};

inline dds_entity_t RawParticipant(int domain) {
  PinLoopback();
  return dds_create_participant(static_cast<dds_domainid_t>(domain), nullptr, nullptr);
}

/// A reader of `dds_topic` ("rt/...") of the reference type: reliable, keep last `depth`,
/// volatile or transient local.
inline dds_entity_t RawReader(dds_entity_t participant, const dds_topic_descriptor_t* type,
                              const std::string& dds_topic, int depth = 10,
                              bool transient_local = false) {
  const dds_entity_t topic =
      dds_create_topic(participant, type, dds_topic.c_str(), nullptr, nullptr);
  if (topic < 0) return topic;
  dds_qos_t* qos = dds_create_qos();
  dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, depth);
  dds_qset_durability(qos,
                      transient_local ? DDS_DURABILITY_TRANSIENT_LOCAL : DDS_DURABILITY_VOLATILE);
  const dds_entity_t reader = dds_create_reader(participant, topic, qos, nullptr);
  dds_delete_qos(qos);
  return reader;
}

inline dds_entity_t RawWriter(dds_entity_t participant, const dds_topic_descriptor_t* type,
                              const std::string& dds_topic) {
  const dds_entity_t topic =
      dds_create_topic(participant, type, dds_topic.c_str(), nullptr, nullptr);
  if (topic < 0) return topic;
  dds_qos_t* qos = dds_create_qos();
  dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 10);
  const dds_entity_t writer = dds_create_writer(participant, topic, qos, nullptr);
  dds_delete_qos(qos);
  return writer;
}

/// Waits up to `timeout_s` for `reader` to match a writer.
inline bool WaitReaderMatched(dds_entity_t reader, double timeout_s = 10) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (std::chrono::steady_clock::now() < deadline) {
    dds_subscription_matched_status_t status{};
    dds_get_subscription_matched_status(reader, &status);
    if (status.current_count > 0) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return false;
}

inline bool WaitWriterMatched(dds_entity_t writer, double timeout_s = 10) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (std::chrono::steady_clock::now() < deadline) {
    dds_publication_matched_status_t status{};
    dds_get_publication_matched_status(writer, &status);
    if (status.current_count > 0) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return false;
}

/// The serialized bytes (4-byte encapsulation header included) of the next sample `reader`
/// receives within `timeout_s`, as they came off the wire; empty when none came.
inline std::vector<uint8_t> TakeCdr(dds_entity_t reader, double timeout_s = 10) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (std::chrono::steady_clock::now() < deadline) {
    struct ddsi_serdata* data = nullptr;
    dds_sample_info_t info;
    const dds_return_t n = dds_takecdr(reader, &data, 1, &info, DDS_ANY_STATE);
    if (n == 1) {
      std::vector<uint8_t> bytes;
      if (info.valid_data) {
        bytes.resize(ddsi_serdata_size(data));
        ddsi_serdata_to_ser(data, 0, bytes.size(), bytes.data());
      }
      ddsi_serdata_unref(data);
      if (!bytes.empty()) return bytes;
      continue;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return {};
}

/// Takes the next sample of type T (a reference struct) within `timeout_s` into `*out` (which
/// the caller frees with dds_sample_free(out, desc, DDS_FREE_CONTENTS)); false when none came.
template <typename T>
bool TakeSample(dds_entity_t reader, T* out, double timeout_s = 10) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (std::chrono::steady_clock::now() < deadline) {
    void* samples[1] = {out};
    dds_sample_info_t info;
    const dds_return_t n = dds_take(reader, samples, &info, 1, 1);
    if (n == 1 && info.valid_data) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return false;
}

}  // namespace saccade::dds::testing
