#include "saccade/core/progress.h"

#include <unistd.h>

#include <cstdio>
#include <utility>

namespace saccade {

ProgressBar::ProgressBar(int total, std::string unit)
    : total_(total), unit_(std::move(unit)), enabled_(::isatty(STDERR_FILENO) != 0) {}

void ProgressBar::Update(int done, double rate) const {
  if (!enabled_) return;
  constexpr int kWidth = 30;
  const int filled = total_ > 0 ? done * kWidth / total_ : kWidth;
  std::fprintf(stderr, "\r[%s%s] %d/%d %s  %.1f fps", std::string(filled, '#').c_str(),
               std::string(kWidth - filled, '.').c_str(), done, total_, unit_.c_str(), rate);
  std::fflush(stderr);
}

void ProgressBar::Finish() const {
  if (enabled_) std::fprintf(stderr, "\n");
}

}  // namespace saccade
