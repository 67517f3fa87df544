#pragma once
// Progress of long work on a terminal: "[#####.....]  12/100 frames  25.3 fps", redrawn in
// place on stderr. Silent when stderr is not a terminal (logs, CI, pipes).
#include <string>

namespace saccade {

class ProgressBar {
 public:
  explicit ProgressBar(int total, std::string unit = "frames");
  /// `done` of the total, at `rate` units per second.
  void Update(int done, double rate) const;
  /// Ends the line (once the work is done or stopped).
  void Finish() const;

 private:
  int total_;
  std::string unit_;
  bool enabled_;
};

}  // namespace saccade
