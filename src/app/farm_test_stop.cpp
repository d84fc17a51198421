#include "app/farm_test_stop.h"

#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>

namespace tessera {

std::function<void(const char*)> farm_test_stop(int32_t rank) {
  const char* spec = std::getenv("TESSERA_TEST_STOP");
  if (spec == nullptr) return {};
  const std::string s = spec;
  const size_t a = s.find(':');
  if (a == std::string::npos || std::atoi(s.substr(0, a).c_str()) != rank) return {};
  const size_t b = s.find(':', a + 1);
  const std::string point = s.substr(a + 1, b == std::string::npos ? std::string::npos : b - a - 1);
  const int nth = b == std::string::npos ? 1 : std::atoi(s.c_str() + b + 1);
  auto seen = std::make_shared<int>(0);
  return [=](const char* reached) {
    if (point != reached || ++*seen != nth) return;
    std::fprintf(stderr, "tessera: rank %d (pid %d) stops itself at %s %d (TESSERA_TEST_STOP)\n", rank,
                 static_cast<int>(getpid()), reached, nth);
    std::fflush(stderr);
    std::raise(SIGSTOP);
  };
}

}  // namespace tessera
