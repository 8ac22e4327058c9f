// SPDX-License-Identifier: BSD-3-Clause
// The serial worker runs its work in the order posted, on one thread other
// than the caller's; the first exception comes back from Wait and the work
// after it is skipped; a worker destroyed with work queued stops.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <thread>
#include <vector>

#include "radargauss/core/serial_worker.hpp"

namespace radargauss {
namespace {

TEST(SerialWorker, RunsInOrderOnItsOwnThread) {
  SerialWorker worker;
  std::vector<int> order;
  std::vector<std::thread::id> threads;
  for (int k = 0; k < 200; ++k) {
    worker.Post([&, k] {
      if (k % 50 == 0) std::this_thread::sleep_for(std::chrono::milliseconds(2));
      order.push_back(k);
      threads.push_back(std::this_thread::get_id());
    });
  }
  worker.Wait();
  ASSERT_EQ(order.size(), 200u);
  for (int k = 0; k < 200; ++k) EXPECT_EQ(order[std::size_t(k)], k);
  for (const std::thread::id& id : threads) EXPECT_EQ(id, threads.front());
  EXPECT_NE(threads.front(), std::this_thread::get_id());
  worker.Wait();  // nothing posted since: returns at once
}

TEST(SerialWorker, TheFirstExceptionComesBackAndTheRestIsSkipped) {
  SerialWorker worker;
  int ran = 0;
  worker.Post([&] { ++ran; });
  worker.Post([] { throw std::runtime_error("first"); });
  worker.Post([] { throw std::logic_error("second"); });
  worker.Post([&] { ++ran; });
  try {
    worker.Wait();
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "first");
  }
  EXPECT_EQ(ran, 1);
  EXPECT_THROW(worker.Wait(), std::runtime_error);  // kept
}

TEST(SerialWorker, StopsWhenDestroyedWithWorkQueued) {
  std::atomic<int> ran{0};
  {
    SerialWorker worker;
    for (int k = 0; k < 1000; ++k) {
      worker.Post([&] {
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
        ++ran;
      });
    }
  }
  EXPECT_LT(ran.load(), 1000);
}

}  // namespace
}  // namespace radargauss
