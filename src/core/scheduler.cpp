// makeScheduler: the one place that maps SchedulerKind to a Scheduler class.
#include "scheduler_detail.hpp"

#include <cmath>
#include <string>

namespace stc {

void validateSchedulerOptions(const SchedulerOptions& options) {
  if (options.queue_count < 1 || options.queue_count > 64) {
    throw InputError("queue_count", "must be in [1, 64], got " + std::to_string(options.queue_count));
  }
  if (!std::isfinite(options.queue_ratio) || options.queue_ratio <= 1.0) {
    throw InputError("queue_ratio", "must be finite and > 1");
  }
  if (!std::isfinite(options.cost_exponent) || options.cost_exponent < 0.0 ||
      options.cost_exponent > 4.0) {
    throw InputError("cost_exponent", "must be in [0, 4]");
  }
}

std::unique_ptr<Scheduler> makeScheduler(const SchedulerOptions& options) {
  validateSchedulerOptions(options);
  switch (options.kind) {
    case SchedulerKind::RoundRobin:
      return std::make_unique<detail::RoundRobinScheduler>();
    case SchedulerKind::Sequential:
      return std::make_unique<detail::SequentialScheduler>(false);
    case SchedulerKind::PerceptualSequential:
      return std::make_unique<detail::SequentialScheduler>(true);
    case SchedulerKind::PriorityQueues:
      return std::make_unique<detail::PriorityQueueScheduler>(options);
  }
  throw InputError("scheduler", "unknown kind");
}

}  // namespace stc
