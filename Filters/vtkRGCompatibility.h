// Where the ParaView and VTK versions RGMC builds against (ParaView 5.11 with VTK 9.2 to ParaView
// 6.1 with VTK 9.6) differ in API or behaviour, in one place. Everything else in the project is
// the same source on every version.
#ifndef vtkRGCompatibility_h
#define vtkRGCompatibility_h

#include "vtkVersion.h" // VTK_VERSION_NUMBER, VTK_VERSION_CHECK

// vtkWindowedSincPolyDataFilter::SetWindowFunction, whose default became the Nuttall window:
// VTK's master of 2024-03-14 (so ParaView 5.13's VTK 9.3.20240617), first released in VTK 9.4.
// Before it, the window was Hamming, with no setting.
#define RGMC_VTK_SINC_HAS_WINDOW_FUNCTION                                                          \
  (VTK_VERSION_NUMBER >= VTK_VERSION_CHECK(9, 3, 20240314))

#endif
// VTK-HeaderTest-Exclude: vtkRGCompatibility.h
