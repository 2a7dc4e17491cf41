#include <cstdio>

#include "msim/version.hpp"

int main() {
  std::printf("msim %s\n", msim::kVersion);
  return 0;
}
