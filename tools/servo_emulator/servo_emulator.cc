#include "servo_emulator/servo_emulator.h"

#include <errno.h>
#include <fcntl.h>
#include <fmt/format.h>
#include <poll.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <set>
#include <utility>

#include "saccade/core/error.h"
#include "saccade/head/joint_profile.h"
#include "saccade/hw/hw_error.h"

namespace saccade::hw {
namespace {

namespace inst = dxl::instruction;
namespace err = dxl::status_error;
namespace tbl = dxl::table;
using dxl::ControlItem;

enum class Access { kRead, kReadWrite };

// One emulated item: range and initial value as in the e-Manual (XM430-W350).
struct ItemSpec {
  ControlItem item;
  Access access;
  bool is_signed;
  int64_t min;
  int64_t max;
  int64_t initial;
};

constexpr Access R = Access::kRead;
constexpr Access RW = Access::kReadWrite;
constexpr uint16_t kFirmwareVersion = 46;
constexpr int kInitialTemperature = 32;  // deg C
constexpr int kInputVoltage = 120;       // 0.1 V: 12.0 V
constexpr int32_t kMiddlePosition = 2048;

// clang-format off
constexpr ItemSpec kItems[] = {
    {tbl::kModelNumber,            R,  false, 0, 65535, dxl::kModelXM430W350},
    {tbl::kModelInformation,       R,  false, 0, 0, 0},
    {tbl::kFirmwareVersion,        R,  false, 0, 255, kFirmwareVersion},
    {tbl::kId,                     RW, false, 0, dxl::kMaxId, 1},
    {tbl::kBaudRate,               RW, false, 0, 7, 1},
    {tbl::kReturnDelayTime,        RW, false, 0, 254, 250},
    {tbl::kDriveMode,              RW, false, 0, 13, 0},
    {tbl::kOperatingMode,          RW, false, 0, 16, 3},
    {tbl::kSecondaryId,            RW, false, 0, 255, 255},
    {tbl::kProtocolType,           RW, false, 1, 2, 2},
    {tbl::kHomingOffset,           RW, true,  -1044479, 1044479, 0},
    {tbl::kMovingThreshold,        RW, false, 0, 1023, 10},
    {tbl::kTemperatureLimit,       RW, false, 0, 100, 80},
    {tbl::kMaxVoltageLimit,        RW, false, 60, 160, 160},
    {tbl::kMinVoltageLimit,        RW, false, 60, 160, 95},
    {tbl::kPwmLimit,               RW, false, 0, 885, 885},
    {tbl::kCurrentLimit,           RW, false, 0, 1193, 1193},
    {tbl::kAccelerationLimit,      RW, false, 0, 32767, 32767},
    {tbl::kVelocityLimit,          RW, false, 0, 1023, 230},
    {tbl::kMaxPositionLimit,       RW, false, 0, 4095, 4095},
    {tbl::kMinPositionLimit,       RW, false, 0, 4095, 0},
    {tbl::kShutdown,               RW, false, 0, 255, 0x34},
    {tbl::kTorqueEnable,           RW, false, 0, 1, 0},
    {tbl::kLed,                    RW, false, 0, 1, 0},
    {tbl::kStatusReturnLevel,      RW, false, 0, 2, 2},
    {tbl::kRegisteredInstruction,  R,  false, 0, 1, 0},
    {tbl::kHardwareErrorStatus,    R,  false, 0, 255, 0},
    {tbl::kVelocityIGain,          RW, false, 0, 16383, 1920},
    {tbl::kVelocityPGain,          RW, false, 0, 16383, 100},
    {tbl::kPositionDGain,          RW, false, 0, 16383, 0},
    {tbl::kPositionIGain,          RW, false, 0, 16383, 0},
    {tbl::kPositionPGain,          RW, false, 0, 16383, 800},
    {tbl::kFeedforward2ndGain,     RW, false, 0, 16383, 0},
    {tbl::kFeedforward1stGain,     RW, false, 0, 16383, 0},
    {tbl::kBusWatchdog,            RW, false, 0, 127, 0},
    {tbl::kGoalPwm,                RW, true,  -885, 885, 885},
    {tbl::kGoalCurrent,            RW, true,  -1193, 1193, 1193},
    {tbl::kGoalVelocity,           RW, true,  -1023, 1023, 0},
    {tbl::kProfileAcceleration,    RW, false, 0, 32767, 0},
    {tbl::kProfileVelocity,        RW, false, 0, 32767, 0},
    {tbl::kGoalPosition,           RW, true,  -1048575, 1048575, kMiddlePosition},
    {tbl::kRealtimeTick,           R,  false, 0, 32767, 0},
    {tbl::kMoving,                 R,  false, 0, 1, 0},
    {tbl::kMovingStatus,           R,  false, 0, 255, 0},
    {tbl::kPresentPwm,             R,  true,  -885, 885, 0},
    {tbl::kPresentCurrent,         R,  true,  -1193, 1193, 0},
    {tbl::kPresentVelocity,        R,  true,  INT32_MIN, INT32_MAX, 0},
    {tbl::kPresentPosition,        R,  true,  INT32_MIN, INT32_MAX, kMiddlePosition},
    {tbl::kVelocityTrajectory,     R,  true,  INT32_MIN, INT32_MAX, 0},
    {tbl::kPositionTrajectory,     R,  true,  INT32_MIN, INT32_MAX, kMiddlePosition},
    {tbl::kPresentInputVoltage,    R,  false, 0, 65535, kInputVoltage},
    {tbl::kPresentTemperature,     R,  false, 0, 255, kInitialTemperature},
};
// clang-format on

// Operating Mode values of the X series: current, velocity, position, extended position,
// current-based position, PWM.
constexpr int kOperatingModes[] = {0, 1, 3, 4, 5, 16};
constexpr int kPositionControlMode = 3;
constexpr int kExtendedPositionControlMode = 4;

// Unit conversions (e-Manual): ticks/s per velocity unit, ticks/s^2 per acceleration unit.
constexpr double kTicksPerSecondPerVelocityUnit =
    dxl::kRpmPerVelocityUnit * dxl::kTicksPerRevolution / 60.0;
constexpr double kTicksPerSecond2PerAccelerationUnit =
    dxl::kRpmPerMinutePerAccelerationUnit * dxl::kTicksPerRevolution / 3600.0;
// Profile Acceleration 0 is infinite: a step in velocity, as far as a 1 ms read can tell.
constexpr double kInfiniteAcceleration = 1e9;  // ticks/s^2

// The item that starts at `address`, or null.
const ItemSpec* ItemAt(uint16_t address) {
  for (const ItemSpec& spec : kItems) {
    if (spec.item.address == address) return &spec;
  }
  return nullptr;
}

// Whether `address` lies inside an item (not at its start).
bool InsideItem(uint16_t address) {
  return std::any_of(std::begin(kItems), std::end(kItems), [address](const ItemSpec& spec) {
    return address > spec.item.address && address < spec.item.address + spec.item.size;
  });
}

using Table = std::array<uint8_t, tbl::kEnd>;

int64_t Get(const Table& table, const ItemSpec& spec) {
  const uint32_t raw = dxl::GetLE(table.data() + spec.item.address, spec.item.size);
  return spec.is_signed ? dxl::SignExtend(raw, spec.item.size) : static_cast<int64_t>(raw);
}

int64_t Get(const Table& table, const ControlItem& item) {
  const ItemSpec* spec = ItemAt(item.address);
  return Get(table, *spec);
}

void Set(Table& table, const ControlItem& item, int64_t value) {
  const std::vector<uint8_t> bytes = dxl::LEBytes(static_cast<uint32_t>(value), item.size);
  std::copy(bytes.begin(), bytes.end(), table.begin() + item.address);
}

double Seconds(std::chrono::steady_clock::duration duration) {
  return std::chrono::duration<double>(duration).count();
}

}  // namespace

struct ServoEmulator::Servo {
  uint8_t id = 0;
  Table table{};
  double position = kMiddlePosition;  // ticks
  double velocity = 0.0;              // ticks/s
  head::JointProfile profile{static_cast<double>(kMiddlePosition)};
  Clock::time_point profile_start{};
  bool moving = false;
  uint8_t hardware_error = 0;
  int temperature = kInitialTemperature;
  bool silent = false;
  std::optional<int32_t> last_goal;
  std::optional<std::vector<uint8_t>> registered;  // Reg Write: address (2 bytes) + data

  bool torque() const { return table[tbl::kTorqueEnable.address] != 0; }
  void Hold(Clock::time_point now) {
    profile = head::JointProfile(position);
    profile_start = now;
    velocity = 0.0;
    moving = false;
  }
};

bool ServoEmulatorOptions::IsValid(std::string* error) const {
  std::string why;
  std::set<uint8_t> seen;
  if (ids.empty()) why = "ids: empty, expected at least one servo";
  for (uint8_t id : ids) {
    if (!why.empty()) break;
    if (id > dxl::kMaxId) {
      why = fmt::format("ids: {} is not a servo id (expected 0..{})", id, dxl::kMaxId);
    } else if (!seen.insert(id).second) {
      why = fmt::format("ids: {} appears twice", id);
    }
  }
  if (why.empty() && !initial_positions.empty() && initial_positions.size() != ids.size()) {
    why = fmt::format("initial_positions: {} values for {} servos", initial_positions.size(),
                      ids.size());
  }
  for (int32_t p : initial_positions) {
    if (why.empty() && (p < 0 || p > 4095)) {
      why = fmt::format("initial_positions: {} ticks, expected 0..4095", p);
    }
  }
  if (why.empty() && !(drop_rate >= 0.0 && drop_rate <= 1.0)) {
    why = fmt::format("drop_rate = {}, expected a probability in [0, 1]", drop_rate);
  }
  if (why.empty() && !(corrupt_rate >= 0.0 && corrupt_rate <= 1.0)) {
    why = fmt::format("corrupt_rate = {}, expected a probability in [0, 1]", corrupt_rate);
  }
  if (why.empty() && update_period.count() <= 0) {
    why = fmt::format("update_period = {} us, expected > 0", update_period.count());
  }
  if (error) *error = why;
  return why.empty();
}

ServoEmulator::ServoEmulator(ServoEmulatorOptions options)
    : options_(std::move(options)), rng_(options_.seed), start_time_(Clock::now()) {
  std::string error;
  if (!options_.IsValid(&error)) {
    throw InvalidArgument("ServoEmulator: options: " + error);
  }
  const Clock::time_point now = Clock::now();
  for (size_t i = 0; i < options_.ids.size(); ++i) {
    auto servo = std::make_unique<Servo>();
    servo->id = options_.ids[i];
    for (const ItemSpec& spec : kItems) Set(servo->table, spec.item, spec.initial);
    Set(servo->table, tbl::kId, servo->id);
    servo->position =
        options_.initial_positions.empty() ? kMiddlePosition : options_.initial_positions[i];
    Set(servo->table, tbl::kGoalPosition, static_cast<int64_t>(servo->position));
    servo->Hold(now);
    servos_.push_back(std::move(servo));
  }
  std::sort(servos_.begin(), servos_.end(),
            [](const auto& a, const auto& b) { return a->id < b->id; });
  UpdateAllLocked(now);
}

ServoEmulator::~ServoEmulator() { Stop(); }

std::string ServoEmulator::Start(const std::string& symlink) {
  if (running()) {
    throw Error("ServoEmulator::Start: already running on " + terminal_->slave_path());
  }
  auto terminal = std::make_unique<PseudoTerminal>(symlink);
  if (pipe2(wake_fds_, O_CLOEXEC | O_NONBLOCK) != 0) {
    throw HardwareError(terminal->slave_path(), "cannot create the emulator's wake-up pipe");
  }
  terminal_ = std::move(terminal);
  thread_ = std::thread([this] { Serve(); });
  return terminal_->slave_path();
}

void ServoEmulator::Stop() {
  if (thread_.joinable()) {
    const char byte = 1;
    (void)::write(wake_fds_[1], &byte, 1);
    thread_.join();
  }
  for (int& fd : wake_fds_) {
    if (fd >= 0) ::close(fd);
    fd = -1;
  }
  terminal_.reset();
}

std::string ServoEmulator::slave_path() const {
  return terminal_ ? terminal_->slave_path() : std::string();
}

void ServoEmulator::Serve() {
  dxl::PacketParser parser;
  const int master = terminal_->master_fd();
  const int period_ms = static_cast<int>(std::max<int64_t>(
      1, std::chrono::ceil<std::chrono::milliseconds>(options_.update_period).count()));
  uint8_t buffer[1024];
  while (true) {
    pollfd fds[2] = {{master, POLLIN, 0}, {wake_fds_[0], POLLIN, 0}};
    const int ready = ::poll(fds, 2, period_ms);
    if (ready < 0 && errno != EINTR) {
      std::this_thread::sleep_for(options_.update_period);  // should not happen; do not spin
    }
    if (ready > 0 && fds[1].revents) return;
    std::vector<uint8_t> out;
    if (ready > 0 && (fds[0].revents & POLLIN)) {
      while (true) {
        const ssize_t n = ::read(master, buffer, sizeof(buffer));
        if (n <= 0) break;
        std::lock_guard<std::mutex> lock(mutex_);
        const std::vector<uint8_t> answer = FeedLocked(parser, buffer, static_cast<size_t>(n));
        out.insert(out.end(), answer.begin(), answer.end());
      }
    } else if (ready > 0 && (fds[0].revents & (POLLHUP | POLLERR))) {
      std::this_thread::sleep_for(options_.update_period);  // nobody on the slave: idle
    }
    // Answer; when the reader does not empty its side, the bytes are lost as on a real bus.
    size_t done = 0;
    while (done < out.size()) {
      const ssize_t n = ::write(master, out.data() + done, out.size() - done);
      if (n > 0) {
        done += static_cast<size_t>(n);
        continue;
      }
      if (n < 0 && errno == EINTR) continue;
      pollfd pfd{master, POLLOUT, 0};
      if (n < 0 && errno == EAGAIN && ::poll(&pfd, 1, 50) > 0) continue;
      break;
    }
    std::lock_guard<std::mutex> lock(mutex_);
    UpdateAllLocked(Clock::now());
  }
}

std::vector<uint8_t> ServoEmulator::Process(const uint8_t* data, size_t size) {
  std::lock_guard<std::mutex> lock(mutex_);
  return FeedLocked(in_process_parser_, data, size);
}

std::vector<uint8_t> ServoEmulator::FeedLocked(dxl::PacketParser& parser, const uint8_t* data,
                                               size_t size) {
  const int64_t crc_before = parser.crc_errors();
  parser.Feed(data, size);
  counters_.crc_errors += parser.crc_errors() - crc_before;
  std::vector<uint8_t> out;
  while (auto packet = parser.Next()) {
    if (packet->is_status()) continue;  // another device's answer: not for us
    ++counters_.instructions_received;
    const std::vector<uint8_t> answer = HandleLocked(*packet, Clock::now());
    if (!answer.empty()) ++counters_.instructions_answered;
    out.insert(out.end(), answer.begin(), answer.end());
  }
  return out;
}

ServoEmulator::Servo* ServoEmulator::FindLocked(uint8_t id) {
  for (auto& servo : servos_) {
    if (servo->id == id) return servo.get();
  }
  return nullptr;
}

const ServoEmulator::Servo* ServoEmulator::FindLocked(uint8_t id) const {
  for (const auto& servo : servos_) {
    if (servo->id == id) return servo.get();
  }
  return nullptr;
}

const ServoEmulator::Servo& ServoEmulator::CheckedLocked(const char* function, uint8_t id) const {
  const Servo* servo = FindLocked(id);
  if (!servo) {
    std::string ids;
    for (const auto& s : servos_) ids += (ids.empty() ? "" : ",") + std::to_string(s->id);
    throw InvalidArgument(
        fmt::format("ServoEmulator::{}: no servo {} on the bus (ids: {})", function, id, ids));
  }
  return *servo;
}

ServoEmulator::Servo& ServoEmulator::CheckedLocked(const char* function, uint8_t id) {
  // The servos live on the heap and are never const themselves.
  return const_cast<Servo&>(std::as_const(*this).CheckedLocked(function, id));
}

void ServoEmulator::UpdateLocked(Servo& servo, Clock::time_point now) const {
  if (servo.torque()) {
    const double t = Seconds(now - servo.profile_start);
    servo.position = servo.profile.Position(t);
    servo.velocity = servo.profile.Velocity(t);
    servo.moving = t < servo.profile.duration();
  } else {
    servo.velocity = 0.0;
    servo.moving = false;
  }
  Table& table = servo.table;
  const auto position = static_cast<int64_t>(std::lround(servo.position));
  const auto velocity =
      static_cast<int64_t>(std::lround(servo.velocity / kTicksPerSecondPerVelocityUnit));
  Set(table, tbl::kPresentPosition, position);
  Set(table, tbl::kPositionTrajectory, position);
  Set(table, tbl::kPresentVelocity, velocity);
  Set(table, tbl::kVelocityTrajectory, velocity);
  Set(table, tbl::kMoving, servo.moving ? 1 : 0);
  Set(table, tbl::kRealtimeTick,
      std::chrono::duration_cast<std::chrono::milliseconds>(now - start_time_).count() % 32768);
  Set(table, tbl::kPresentTemperature, servo.temperature);
  Set(table, tbl::kHardwareErrorStatus, servo.hardware_error);
  if (servo.temperature > Get(table, tbl::kTemperatureLimit) &&
      !(servo.hardware_error & dxl::hardware_error::kOverheating)) {
    RaiseLocked(servo, dxl::hardware_error::kOverheating, now);
  }
}

void ServoEmulator::UpdateAllLocked(Clock::time_point now) {
  for (auto& servo : servos_) UpdateLocked(*servo, now);
}

void ServoEmulator::RaiseLocked(Servo& servo, uint8_t bits, Clock::time_point now) const {
  servo.hardware_error |= bits;
  Set(servo.table, tbl::kHardwareErrorStatus, servo.hardware_error);
  if ((bits & Get(servo.table, tbl::kShutdown)) && servo.torque()) {
    Set(servo.table, tbl::kTorqueEnable, 0);
    servo.Hold(now);  // the motor's output drops to 0: it stops where it is
    UpdateLocked(servo, now);
  }
}

void ServoEmulator::ReplanLocked(Servo& servo, Clock::time_point now) {
  const Table& table = servo.table;
  const int64_t velocity_limit = Get(table, tbl::kVelocityLimit);
  const int64_t profile_velocity = Get(table, tbl::kProfileVelocity);
  const int64_t velocity_units =
      profile_velocity == 0 ? velocity_limit : std::min(profile_velocity, velocity_limit);
  if (velocity_units == 0) {  // Velocity Limit 0: it cannot move
    servo.Hold(now);
    return;
  }
  int64_t acceleration_units = Get(table, tbl::kProfileAcceleration);
  const int64_t acceleration_limit = Get(table, tbl::kAccelerationLimit);
  if (acceleration_units > acceleration_limit) acceleration_units = acceleration_limit;
  const double vmax = static_cast<double>(velocity_units) * kTicksPerSecondPerVelocityUnit;
  const double amax = acceleration_units == 0 ? kInfiniteAcceleration
                                              : static_cast<double>(acceleration_units) *
                                                    kTicksPerSecond2PerAccelerationUnit;
  const double goal = static_cast<double>(Get(table, tbl::kGoalPosition));
  const double x0 = servo.position;
  const double v0 = std::clamp(servo.velocity, -vmax, vmax);
  const double stop = x0 + v0 * std::abs(v0) / (2 * amax);
  // The goal was checked against the position limits; the range only has to contain the
  // start and its braking point too (the limits may have changed with the torque off).
  double lo = std::min({goal, x0, stop});
  double hi = std::max({goal, x0, stop});
  if (Get(table, tbl::kOperatingMode) == kPositionControlMode) {
    lo = std::min(lo, static_cast<double>(Get(table, tbl::kMinPositionLimit)));
    hi = std::max(hi, static_cast<double>(Get(table, tbl::kMaxPositionLimit)));
  }
  if (hi - lo < 1.0) hi = lo + 1.0;
  const head::JointLimits limits{lo, hi, vmax, amax};
  servo.profile = head::JointProfile::Plan(limits, x0, v0, goal, 0.0);
  servo.profile_start = now;
}

void ServoEmulator::ResetRamLocked(Servo& servo, Clock::time_point now) {
  for (const ItemSpec& spec : kItems) {
    if (spec.item.address >= tbl::kRamStart) Set(servo.table, spec.item, spec.initial);
  }
  servo.hardware_error = 0;
  servo.registered.reset();
  servo.Hold(now);
  Set(servo.table, tbl::kGoalPosition, std::lround(servo.position));
  UpdateLocked(servo, now);
}

uint8_t ServoEmulator::ValidateWriteLocked(const Servo& servo, uint16_t address,
                                           const std::vector<uint8_t>& data) const {
  const size_t end = static_cast<size_t>(address) + data.size();
  if (data.empty() || address >= tbl::kEnd || end > tbl::kEnd) return err::kAccessError;
  Table after = servo.table;
  std::copy(data.begin(), data.end(), after.begin() + address);
  bool goal_written = false;
  bool goal_velocity_written = false;
  for (size_t p = address; p < end;) {
    const ItemSpec* spec = ItemAt(static_cast<uint16_t>(p));
    if (!spec) {
      return InsideItem(static_cast<uint16_t>(p)) ? err::kDataLengthError : err::kAccessError;
    }
    if (p + spec->item.size > end) return err::kDataLengthError;
    if (spec->access == Access::kRead) return err::kAccessError;
    if (p < tbl::kRamStart && servo.torque()) return err::kAccessError;  // EEPROM locked
    const int64_t value = Get(after, *spec);
    if (value < spec->min || value > spec->max) return err::kDataRangeError;
    if (spec->item.address == tbl::kOperatingMode.address &&
        std::find(std::begin(kOperatingModes), std::end(kOperatingModes), value) ==
            std::end(kOperatingModes)) {
      return err::kDataRangeError;
    }
    if (spec->item.address == tbl::kTorqueEnable.address && value == 1 && !servo.torque() &&
        (servo.hardware_error & Get(servo.table, tbl::kShutdown))) {
      return err::kResultFail;  // shut down: only a reboot brings the torque back
    }
    goal_written |= spec->item.address == tbl::kGoalPosition.address;
    goal_velocity_written |= spec->item.address == tbl::kGoalVelocity.address;
    p += spec->item.size;
  }
  if (goal_written && Get(after, tbl::kOperatingMode) == kPositionControlMode) {
    const int64_t goal = Get(after, tbl::kGoalPosition);
    if (goal < Get(after, tbl::kMinPositionLimit) || goal > Get(after, tbl::kMaxPositionLimit)) {
      return err::kDataLimitError;
    }
  }
  if (goal_velocity_written &&
      std::abs(Get(after, tbl::kGoalVelocity)) > Get(after, tbl::kVelocityLimit)) {
    return err::kDataLimitError;
  }
  return 0;
}

uint8_t ServoEmulator::WriteLocked(Servo& servo, uint16_t address, const std::vector<uint8_t>& data,
                                   Clock::time_point now) {
  const uint8_t error = ValidateWriteLocked(servo, address, data);
  if (error) return error;
  const bool torque_before = servo.torque();
  std::copy(data.begin(), data.end(), servo.table.begin() + address);
  const auto written = [&](const ControlItem& item) {
    return item.address >= address && item.address < address + data.size();
  };
  servo.id = servo.table[tbl::kId.address];
  const bool goal_written = written(tbl::kGoalPosition);
  if (servo.torque() && !torque_before) {
    servo.Hold(now);
    // Torque on holds the present position, unless this very write also sets a goal.
    if (!goal_written) Set(servo.table, tbl::kGoalPosition, std::lround(servo.position));
  } else if (!servo.torque() && torque_before) {
    servo.Hold(now);
  }
  if (goal_written) {
    servo.last_goal = static_cast<int32_t>(Get(servo.table, tbl::kGoalPosition));
    if (servo.torque()) ReplanLocked(servo, now);
  }
  if (written(tbl::kId)) {
    std::sort(servos_.begin(), servos_.end(),
              [](const auto& a, const auto& b) { return a->id < b->id; });
  }
  UpdateLocked(servo, now);
  return 0;
}

uint8_t ServoEmulator::ReadLocked(const Servo& servo, uint16_t address, uint16_t length,
                                  std::vector<uint8_t>* data) const {
  if (length == 0) return err::kDataLengthError;
  if (static_cast<size_t>(address) + length > tbl::kEnd) return err::kAccessError;
  data->assign(servo.table.begin() + address, servo.table.begin() + address + length);
  return 0;
}

void ServoEmulator::AppendStatusLocked(std::vector<uint8_t>& out, const Servo& servo, uint8_t id,
                                       uint8_t error, std::vector<uint8_t> params) {
  if (servo.hardware_error) error |= err::kAlert;
  std::vector<uint8_t> bytes = dxl::EncodePacket({id, inst::kStatus, error, std::move(params)});
  if (options_.corrupt_rate > 0.0 &&
      std::uniform_real_distribution<double>(0.0, 1.0)(rng_) < options_.corrupt_rate) {
    // Flip one byte from INST to the CRC: the header and LEN stay intact, the CRC fails.
    std::uniform_int_distribution<size_t> where(dxl::kPacketPrefixSize, bytes.size() - 1);
    std::uniform_int_distribution<int> mask(1, 255);
    bytes[where(rng_)] ^= static_cast<uint8_t>(mask(rng_));
    ++counters_.corrupted;
  }
  ++counters_.status_packets;
  out.insert(out.end(), bytes.begin(), bytes.end());
}

std::vector<uint8_t> ServoEmulator::HandleLocked(const dxl::Packet& packet, Clock::time_point now) {
  std::vector<uint8_t> out;
  if (options_.drop_rate > 0.0 &&
      std::uniform_real_distribution<double>(0.0, 1.0)(rng_) < options_.drop_rate) {
    ++counters_.dropped;
    return out;
  }
  UpdateAllLocked(now);
  const bool broadcast = packet.id == dxl::kBroadcastId;
  const std::vector<uint8_t>& p = packet.params;
  // The servos this packet addresses directly, in ID order (not the silent ones).
  std::vector<Servo*> targets;
  for (auto& servo : servos_) {
    if (!servo->silent && (broadcast || servo->id == packet.id)) targets.push_back(servo.get());
  }
  // Status Return Level: 0 answers Ping only, 1 also reads, 2 everything.
  const auto answers = [](int64_t level, uint8_t instruction) {
    if (instruction == inst::kPing) return true;
    if (instruction == inst::kRead || instruction == inst::kSyncRead ||
        instruction == inst::kBulkRead) {
      return level >= 1;
    }
    return level >= 2;
  };
  const auto level_of = [](const Servo& servo) {
    return static_cast<int64_t>(servo.table[tbl::kStatusReturnLevel.address]);
  };
  // A servo answers from the ID it was addressed by and at the Status Return Level it had
  // when the instruction arrived, even when the instruction changes them.
  std::map<const Servo*, std::pair<uint8_t, int64_t>> before;
  for (const Servo* servo : targets) before[servo] = {servo->id, level_of(*servo)};
  const auto reply = [&](Servo& servo, uint8_t error, std::vector<uint8_t> params = {}) {
    const auto& [id, level] = before.at(&servo);
    if (!broadcast && answers(level, packet.instruction)) {
      AppendStatusLocked(out, servo, id, error, std::move(params));
    }
  };
  const auto silent_or_missing = [&](uint8_t id) -> Servo* {
    Servo* servo = FindLocked(id);
    return servo && !servo->silent ? servo : nullptr;
  };

  switch (packet.instruction) {
    case inst::kPing:
      for (Servo* servo : targets) {
        std::vector<uint8_t> params = dxl::LEBytes(dxl::kModelXM430W350, 2);
        params.push_back(static_cast<uint8_t>(kFirmwareVersion));
        AppendStatusLocked(out, *servo, servo->id, 0, std::move(params));  // even for broadcast
      }
      break;
    case inst::kRead:
      if (broadcast) break;
      for (Servo* servo : targets) {
        if (p.size() != 4) {
          reply(*servo, err::kDataLengthError);
          continue;
        }
        std::vector<uint8_t> data;
        const uint8_t error = ReadLocked(*servo, static_cast<uint16_t>(dxl::GetLE(p.data(), 2)),
                                         static_cast<uint16_t>(dxl::GetLE(p.data() + 2, 2)), &data);
        reply(*servo, error, error ? std::vector<uint8_t>{} : std::move(data));
      }
      break;
    case inst::kWrite:
    case inst::kRegWrite:
      for (Servo* servo : targets) {
        if (p.size() < 3) {
          reply(*servo, err::kDataLengthError);
          continue;
        }
        const auto address = static_cast<uint16_t>(dxl::GetLE(p.data(), 2));
        const std::vector<uint8_t> data(p.begin() + 2, p.end());
        if (packet.instruction == inst::kWrite) {
          reply(*servo, WriteLocked(*servo, address, data, now));
          continue;
        }
        const uint8_t error = ValidateWriteLocked(*servo, address, data);
        if (!error) {
          servo->registered = p;
          Set(servo->table, tbl::kRegisteredInstruction, 1);
        }
        reply(*servo, error);
      }
      break;
    case inst::kAction:
      for (Servo* servo : targets) {
        if (!servo->registered) {
          reply(*servo, err::kInstructionError);  // Action without Reg Write
          continue;
        }
        const std::vector<uint8_t> registered = *servo->registered;
        servo->registered.reset();
        Set(servo->table, tbl::kRegisteredInstruction, 0);
        const std::vector<uint8_t> data(registered.begin() + 2, registered.end());
        reply(*servo, WriteLocked(*servo, static_cast<uint16_t>(dxl::GetLE(registered.data(), 2)),
                                  data, now));
      }
      break;
    case inst::kFactoryReset: {
      const uint8_t option = p.empty() ? 0xFF : p[0];
      if (broadcast && option == 0xFF) break;  // e-Manual: refused for the broadcast id
      for (Servo* servo : targets) {
        if (option != 0xFF && option != 0x01 && option != 0x02) {
          reply(*servo, err::kDataRangeError);
          continue;
        }
        reply(*servo, 0);
        const uint8_t id = servo->id;
        const uint8_t baud = servo->table[tbl::kBaudRate.address];
        for (const ItemSpec& spec : kItems) Set(servo->table, spec.item, spec.initial);
        if (option != 0xFF) Set(servo->table, tbl::kId, id);
        if (option == 0x02) Set(servo->table, tbl::kBaudRate, baud);
        servo->id = servo->table[tbl::kId.address];
        ResetRamLocked(*servo, now);
      }
      std::sort(servos_.begin(), servos_.end(),
                [](const auto& a, const auto& b) { return a->id < b->id; });
      break;
    }
    case inst::kReboot:
      for (Servo* servo : targets) {
        reply(*servo, 0);  // the servo answers, then reboots
        ResetRamLocked(*servo, now);
      }
      break;
    case inst::kClear:
      for (Servo* servo : targets) {
        static constexpr uint8_t kClearMultiTurn[] = {0x01, 0x44, 0x58, 0x4C, 0x22};
        if (p.size() != 5 || !std::equal(p.begin(), p.end(), std::begin(kClearMultiTurn))) {
          reply(*servo, err::kDataRangeError);
        } else if (servo->moving) {
          reply(*servo, err::kResultFail);  // only a servo at rest may be cleared
        } else {
          servo->position = std::fmod(std::fmod(servo->position, 4096.0) + 4096.0, 4096.0);
          servo->Hold(now);
          UpdateLocked(*servo, now);
          reply(*servo, 0);
        }
      }
      break;
    case inst::kSyncRead:
      if (!broadcast || p.size() < 5) break;
      {
        const auto address = static_cast<uint16_t>(dxl::GetLE(p.data(), 2));
        const auto length = static_cast<uint16_t>(dxl::GetLE(p.data() + 2, 2));
        for (size_t i = 4; i < p.size(); ++i) {
          Servo* servo = silent_or_missing(p[i]);
          if (!servo || !answers(level_of(*servo), inst::kSyncRead)) continue;
          std::vector<uint8_t> data;
          const uint8_t error = ReadLocked(*servo, address, length, &data);
          AppendStatusLocked(out, *servo, servo->id, error,
                             error ? std::vector<uint8_t>{} : std::move(data));
        }
      }
      break;
    case inst::kSyncWrite:
      if (!broadcast || p.size() < 4) break;
      {
        const auto address = static_cast<uint16_t>(dxl::GetLE(p.data(), 2));
        const size_t length = dxl::GetLE(p.data() + 2, 2);
        if (length == 0 || (p.size() - 4) % (length + 1) != 0) break;  // malformed: ignored
        for (size_t i = 4; i < p.size(); i += length + 1) {
          Servo* servo = silent_or_missing(p[i]);
          if (!servo) continue;
          const std::vector<uint8_t> data(p.begin() + static_cast<std::ptrdiff_t>(i + 1),
                                          p.begin() + static_cast<std::ptrdiff_t>(i + 1 + length));
          WriteLocked(*servo, address, data, now);
        }
      }
      break;
    case inst::kBulkRead:
      if (!broadcast || p.size() % 5 != 0) break;
      for (size_t i = 0; i < p.size(); i += 5) {
        Servo* servo = silent_or_missing(p[i]);
        if (!servo || !answers(level_of(*servo), inst::kBulkRead)) continue;
        std::vector<uint8_t> data;
        const uint8_t error =
            ReadLocked(*servo, static_cast<uint16_t>(dxl::GetLE(p.data() + i + 1, 2)),
                       static_cast<uint16_t>(dxl::GetLE(p.data() + i + 3, 2)), &data);
        AppendStatusLocked(out, *servo, servo->id, error,
                           error ? std::vector<uint8_t>{} : std::move(data));
      }
      break;
    case inst::kBulkWrite:
      if (!broadcast) break;
      for (size_t i = 0; i + 5 <= p.size();) {
        const size_t length = dxl::GetLE(p.data() + i + 3, 2);
        if (i + 5 + length > p.size()) break;  // truncated: the rest is ignored
        Servo* servo = silent_or_missing(p[i]);
        if (servo) {
          const std::vector<uint8_t> data(p.begin() + static_cast<std::ptrdiff_t>(i + 5),
                                          p.begin() + static_cast<std::ptrdiff_t>(i + 5 + length));
          WriteLocked(*servo, static_cast<uint16_t>(dxl::GetLE(p.data() + i + 1, 2)), data, now);
        }
        i += 5 + length;
      }
      break;
    default:
      for (Servo* servo : targets) reply(*servo, err::kInstructionError);
      break;
  }
  return out;
}

void ServoEmulator::SetDropRate(double rate) {
  if (!(rate >= 0.0 && rate <= 1.0)) {
    throw InvalidArgument(fmt::format(
        "ServoEmulator::SetDropRate: rate = {}, expected a probability in [0, 1]", rate));
  }
  std::lock_guard<std::mutex> lock(mutex_);
  options_.drop_rate = rate;
}

void ServoEmulator::SetCorruptRate(double rate) {
  if (!(rate >= 0.0 && rate <= 1.0)) {
    throw InvalidArgument(fmt::format(
        "ServoEmulator::SetCorruptRate: rate = {}, expected a probability in [0, 1]", rate));
  }
  std::lock_guard<std::mutex> lock(mutex_);
  options_.corrupt_rate = rate;
}

void ServoEmulator::SetSilent(uint8_t id, bool silent) {
  std::lock_guard<std::mutex> lock(mutex_);
  CheckedLocked("SetSilent", id).silent = silent;
}

void ServoEmulator::InjectHardwareError(uint8_t id, uint8_t bits) {
  std::lock_guard<std::mutex> lock(mutex_);
  Servo& servo = CheckedLocked("InjectHardwareError", id);
  const Clock::time_point now = Clock::now();
  UpdateLocked(servo, now);
  RaiseLocked(servo, bits, now);
}

void ServoEmulator::SetTemperature(uint8_t id, int celsius) {
  if (celsius < 0 || celsius > 255) {
    throw InvalidArgument(fmt::format(
        "ServoEmulator::SetTemperature: servo {}: {} deg C, expected 0..255", id, celsius));
  }
  std::lock_guard<std::mutex> lock(mutex_);
  Servo& servo = CheckedLocked("SetTemperature", id);
  servo.temperature = celsius;
  UpdateLocked(servo, Clock::now());
}

ServoSnapshot ServoEmulator::SnapshotLocked(const Servo& servo) const {
  ServoSnapshot s;
  s.id = servo.id;
  s.position = static_cast<int32_t>(Get(servo.table, tbl::kPresentPosition));
  s.goal = static_cast<int32_t>(Get(servo.table, tbl::kGoalPosition));
  s.velocity = static_cast<int32_t>(Get(servo.table, tbl::kPresentVelocity));
  s.velocity_ticks = servo.velocity;
  s.torque = servo.torque();
  s.moving = servo.moving;
  s.hardware_error = servo.hardware_error;
  s.temperature = servo.temperature;
  s.silent = servo.silent;
  return s;
}

ServoSnapshot ServoEmulator::Snapshot(uint8_t id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  Servo servo = CheckedLocked("Snapshot", id);  // a copy, advanced to now
  UpdateLocked(servo, Clock::now());
  return SnapshotLocked(servo);
}

std::vector<ServoSnapshot> ServoEmulator::Snapshots() const {
  std::lock_guard<std::mutex> lock(mutex_);
  const Clock::time_point now = Clock::now();
  std::vector<ServoSnapshot> out;
  for (const auto& servo : servos_) {
    Servo copy = *servo;
    UpdateLocked(copy, now);
    out.push_back(SnapshotLocked(copy));
  }
  return out;
}

EmulatorCounters ServoEmulator::counters() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return counters_;
}

std::optional<int32_t> ServoEmulator::last_accepted_goal(uint8_t id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return CheckedLocked("last_accepted_goal", id).last_goal;
}

std::vector<uint8_t> ServoEmulator::ids() const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<uint8_t> out;
  for (const auto& servo : servos_) out.push_back(servo->id);
  return out;
}

}  // namespace saccade::hw
