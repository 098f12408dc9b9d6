// The controller of one run of a plugin filter (private to the module): the filter's own, or a
// dummy one when it has none, so that every path runs its collective calls on one rank.
#ifndef vtkRGRunController_h
#define vtkRGRunController_h

#include "vtkDummyController.h"
#include "vtkMultiProcessController.h"
#include "vtkNew.h"

namespace rgmc
{

/// `controller`, or a vtkDummyController (owned, for the run's lifetime) when it is null. Used as
/// `rgmc::RunController controller(this->Controller); rgmc::Ranks ranks(controller);`.
class RunController
{
public:
  explicit RunController(vtkMultiProcessController* controller)
    : Controller(controller ? controller : this->Single.Get())
  {
  }
  RunController(const RunController&) = delete;
  RunController& operator=(const RunController&) = delete;

  vtkMultiProcessController* Get() const { return this->Controller; }
  operator vtkMultiProcessController*() const { return this->Controller; }

private:
  vtkNew<vtkDummyController> Single; // before Controller, which may point to it
  vtkMultiProcessController* Controller;
};

} // namespace rgmc

#endif
