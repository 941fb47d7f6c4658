#include "cli/interrupt.hpp"

#include <csignal>
#include <ctime>
#include <initializer_list>
#include <pthread.h>

namespace hemotree {

struct InterruptRequests::Masks {
  sigset_t blocked, previous;
};

InterruptRequests::InterruptRequests() : masks_(std::make_unique<Masks>()) {
  sigemptyset(&masks_->blocked);
  sigaddset(&masks_->blocked, SIGINT);
  sigaddset(&masks_->blocked, SIGTERM);
  sigaddset(&masks_->blocked, SIGHUP);
  pthread_sigmask(SIG_BLOCK, &masks_->blocked, &masks_->previous);
}

InterruptRequests::~InterruptRequests() { pthread_sigmask(SIG_SETMASK, &masks_->previous, nullptr); }

int InterruptRequests::poll() {
  sigset_t pending;
  if (sigpending(&pending) != 0) return 0;
  for (const int s : {SIGINT, SIGTERM, SIGHUP})
    if (sigismember(&pending, s) == 1) {
      sigset_t one;
      sigemptyset(&one);
      sigaddset(&one, s);
      const timespec now{0, 0};
      sigtimedwait(&one, nullptr, &now);  // consume it
      return s;
    }
  return 0;
}

const char* InterruptRequests::name(int signal_number) {
  switch (signal_number) {
    case SIGINT: return "SIGINT";
    case SIGTERM: return "SIGTERM";
    case SIGHUP: return "SIGHUP";
    default: return "a signal";
  }
}

}  // namespace hemotree
