// The controller of an MPI test: Open MPI's (or any MPI's) under mpiexec, or one process alone
// with --dummy (for running a test by hand or under a debugger without mpiexec).
#ifndef rgmcTestController_h
#define rgmcTestController_h

#include "vtkDummyController.h"
#include "vtkMPIController.h"
#include "vtkSmartPointer.h"

#include "rgmcCheck.h"
#include "rgmcThreadCompare.h"

#include <iostream>
#include <string>

namespace rgmc_test
{

/// Initializes the test's controller (a vtkDummyController when the first argument is
/// --dummy, else MPI) and makes it the global one, for the filters' defaults.
inline vtkSmartPointer<vtkMultiProcessController> StartController(int& argc, char**& argv)
{
  ParseThreads(argc, argv); // --threads N anywhere: the filters on N threads too
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

/// Ends an MPI test: the failed checks summed over the ranks, said by rank 0 after `name`
/// ("TestX on N ranks: ..." plus `detail`), the controller finalized; returns main's status.
inline int Finish(
  vtkMultiProcessController* controller, const std::string& name, const std::string& detail = "")
{
  long long failures = Failures(), total = 0;
  controller->AllReduce(&failures, &total, 1, vtkCommunicator::SUM_OP);
  if (controller->GetLocalProcessId() == 0)
  {
    std::cout << name << " on " << controller->GetNumberOfProcesses() << " ranks: " << detail
              << total << " failed checks\n";
  }
  controller->Finalize();
  return total == 0 ? 0 : 1;
}

} // namespace rgmc_test

#endif
