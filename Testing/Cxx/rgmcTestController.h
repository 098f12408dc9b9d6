// The controller of an MPI test: Open MPI's (or any MPI's) under mpiexec, or one process alone
// with --dummy (for running a test by hand or under a debugger without mpiexec).
#ifndef rgmcTestController_h
#define rgmcTestController_h

#include "vtkDummyController.h"
#include "vtkMPIController.h"
#include "vtkSmartPointer.h"

#include <string>

namespace rgmc_test
{

/// Initializes the test's controller (a vtkDummyController when the first argument is
/// --dummy, else MPI) and makes it the global one, for the filters' defaults.
inline vtkSmartPointer<vtkMultiProcessController> StartController(int& argc, char**& argv)
{
  vtkSmartPointer<vtkMultiProcessController> controller;
  if (argc > 1 && std::string(argv[1]) == "--dummy")
  {
    controller = vtkSmartPointer<vtkDummyController>::New();
  }
  else
  {
    controller = vtkSmartPointer<vtkMPIController>::New();
  }
  controller->Initialize(&argc, &argv);
  vtkMultiProcessController::SetGlobalController(controller);
  return controller;
}

} // namespace rgmc_test

#endif
