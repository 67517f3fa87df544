#pragma once
// A recording played back as the robot (`saccade run PIPELINE --play FILE.mcap`): every ROS 2
// message of an MCAP file (record/recorder.h's, or rosbag2's of saccade's topics) published
// again on DDS, on its topic, as the robot published it, so that a pipeline reading topics
// (pipelines/perception.yaml) runs on the recording exactly as on the live robot. JSON
// channels and types saccade has no ROS 2 form of are not played (skipped() names them).
//
// Messages go out a step at a time (those of one log time, in file order), paced:
//   lockstep   after each step, wait for the answer of every lockstep writer on the command
//              topic (a pipeline's `{topic: head/command, lockstep: true}` output, as the
//              robot's head does): the pipeline sees each step, and computes what it computed
//              live, bit for bit (default);
//   recorded   at the recorded rate times `speed` (wall clock);
//   fast       as fast as they can be published (a reader keeps the newest: frames are skipped).
//
// Threads: the player runs on a thread of its own; its methods are called from one other.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace saccade::record {

struct PlayOptions {
  std::string pace = "lockstep";  ///< lockstep | recorded | fast
  double speed = 1.0;             ///< recorded pace: recorded seconds per wall second, > 0
  /// lockstep: how long to wait for the pipeline's lockstep writer to appear before the first
  /// step, and for its answer to each step (then it steps on, counting the step late).
  double start_wait_s = 30.0;
  double step_wait_s = 10.0;
  std::string command_topic = "head/command";  ///< lockstep answers, under the namespace
};

/// What a play did so far.
struct PlayStats {
  int64_t steps = 0;      ///< of the recording, published
  uint64_t messages = 0;  ///< published
  int64_t late = 0;       ///< lockstep steps whose answer did not come in time
  bool finished = false;  ///< every step published (and, in lockstep, answered)
};

class McapPlayer {
 public:
  /// Reads `file` and makes a DDS writer for each of its ROS 2 channels, on the domain that the
  /// pipeline's `transport:` map names (dds/transport.h; the namespace resolves the command
  /// topic). Throws saccade::FileError for a file that cannot be read (McapReader's errors),
  /// InvalidArgument for options out of range, a recording with no ROS 2 message or no step.
  McapPlayer(const std::filesystem::path& file, const nlohmann::json& transport,
             PlayOptions options = {});
  ~McapPlayer();  ///< stops playing
  McapPlayer(const McapPlayer&) = delete;
  McapPlayer& operator=(const McapPlayer&) = delete;

  /// Starts playing on the player's thread.
  void Start();
  /// Stops playing and waits for the thread. Throws what playing threw (a damaged message:
  /// InvalidArgument naming its topic; a file that went bad: FileError). Idempotent.
  PlayStats Stop();
  PlayStats stats() const;
  /// The log time (s) of the recording's last step: a pipeline stepping on the recording's
  /// stamps is done once its step reaches it.
  double last_time() const;
  /// "topic (why)" of each channel not played.
  const std::vector<std::string>& skipped() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace saccade::record
