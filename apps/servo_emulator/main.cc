// saccade-servo-emulator: placeholder until the emulator lands (issue 7).
#include <cstdio>

int main() {
  std::fputs("saccade-servo-emulator: not built yet\n", stderr);
  return 1;
}
