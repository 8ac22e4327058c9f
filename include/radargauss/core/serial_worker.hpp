// SPDX-License-Identifier: BSD-3-Clause
// One thread that runs the work handed to it in the order it was handed
// (SLAM's back end beside its odometry, docs/design/slam.md "SLAM"). The first
// exception a piece of work throws is kept, the work after it is skipped,
// and Wait rethrows it.
//
//   SerialWorker worker;
//   worker.Post([&] { Search(keyframe); });
//   worker.Wait();  // everything posted is done
#pragma once

#include <condition_variable>
#include <deque>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>

namespace radargauss {

class SerialWorker {
 public:
  SerialWorker();
  // Stops after the work under way; what is still queued is dropped.
  ~SerialWorker();
  SerialWorker(const SerialWorker&) = delete;
  SerialWorker& operator=(const SerialWorker&) = delete;

  void Post(std::function<void()> work);
  // Blocks until everything posted so far has run; rethrows the first exception.
  void Wait();

 private:
  void Run();

  std::mutex mutex_;
  std::condition_variable posted_, done_;
  std::deque<std::function<void()>> queue_;
  bool busy_ = false, stopping_ = false;
  std::exception_ptr error_;
  std::thread thread_;  // last: started once the rest is ready
};

}  // namespace radargauss
