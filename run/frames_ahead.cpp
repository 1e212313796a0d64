#include "run/frames_ahead.hpp"

#include <exception>
#include <memory>

#include "common/units.hpp"

namespace stvl::run {

FramesAhead::FramesAhead(pipeline::Pipeline& pipeline, double duration_s)
    : pipeline_(pipeline), duration_s_(duration_s) {
  pipeline_.set_world_snapshots(true);
  pipeline_.release_gl_contexts();  // the capturing thread draws from now on
}

FramesAhead::~FramesAhead() {
  for (auto& frame : in_flight_) {
    try {
      frame.get();
    } catch (const std::exception&) {  // a frame the loop did not take: its error is of no use now
    }
  }
  try {
    capture_.submit([this] { pipeline_.release_gl_contexts(); });  // so that the renderers can be freed here
    capture_.finish();
  } catch (const std::exception&) {
  }
}

void FramesAhead::submit() {
  auto captured = std::make_shared<std::promise<pipeline::Frame*>>();
  std::shared_future<pipeline::Frame*> frame = captured->get_future().share();
  capture_.submit([this, captured] {
    try {
      if (stopped_ || pipeline_.next_time_s() > duration_s_ + kTimeEpsilon_s) {
        stopped_ = true;
        captured->set_value(nullptr);
        return;
      }
      pipeline::Frame& f = pipeline_.capture();
      stopped_ = !f.robot_upright;
      captured->set_value(&f);
    } catch (...) {
      stopped_ = true;
      captured->set_exception(std::current_exception());
    }
  });
  auto sensed = std::make_shared<std::promise<const pipeline::Frame*>>();
  in_flight_.push_back(sensed->get_future());
  sense_.submit([this, frame, sensed] {
    try {
      pipeline::Frame* f = frame.get();
      if (f) pipeline_.sense(*f);
      sensed->set_value(f);
    } catch (...) {
      sensed->set_exception(std::current_exception());
    }
  });
}

const pipeline::Frame* FramesAhead::next() {
  // The frame the loop held is done with: as many in flight as the pipeline has frames in turn, then one is taken.
  while (in_flight_.size() < pipeline::Pipeline::kFramesInTurn) submit();
  std::future<const pipeline::Frame*> frame = std::move(in_flight_.front());
  in_flight_.pop_front();
  return frame.get();
}

}  // namespace stvl::run
