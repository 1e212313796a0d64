#pragma once
// Runs tasks one after another on a background thread, in submission order, so that slow output (the bag)
// overlaps with the next frame. At most `max_pending` tasks wait; submit() blocks beyond that. The first
// exception a task throws is rethrown by the next submit() or finish().
#include <condition_variable>
#include <deque>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <utility>

namespace stvl {

class SerialWorker {
 public:
  explicit SerialWorker(std::size_t max_pending = 4) : max_pending_(max_pending), thread_([this] { loop(); }) {}
  // Discards tasks not yet started (an interrupted run) and joins.
  ~SerialWorker() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      tasks_.clear();
      stop_ = true;
    }
    changed_.notify_all();
    thread_.join();
  }
  SerialWorker(const SerialWorker&) = delete;
  SerialWorker& operator=(const SerialWorker&) = delete;

  void submit(std::function<void()> task) {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [&] { return tasks_.size() < max_pending_ || error_; });
    rethrow(lock);
    tasks_.push_back(std::move(task));
    changed_.notify_all();
  }
  // Waits until every submitted task has run.
  void finish() {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [&] { return (tasks_.empty() && !busy_) || error_; });
    rethrow(lock);
  }

 private:
  void rethrow(std::unique_lock<std::mutex>&) {
    if (error_) std::rethrow_exception(std::exchange(error_, nullptr));
  }
  void loop() {
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
      changed_.wait(lock, [&] { return stop_ || !tasks_.empty(); });
      if (tasks_.empty()) return;
      auto task = std::move(tasks_.front());
      tasks_.pop_front();
      busy_ = true;
      lock.unlock();
      std::exception_ptr error;
      try {
        task();
      } catch (...) {
        error = std::current_exception();
      }
      lock.lock();
      busy_ = false;
      if (error && !error_) error_ = error, tasks_.clear();
      changed_.notify_all();
    }
  }

  std::size_t max_pending_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<std::function<void()>> tasks_;
  std::exception_ptr error_;
  bool busy_ = false, stop_ = false;
  std::thread thread_;  // last: starts after the members it uses
};

}  // namespace stvl
