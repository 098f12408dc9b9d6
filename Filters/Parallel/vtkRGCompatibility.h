// Where the ParaView and VTK versions RGMC builds against (ParaView 5.11 with VTK 9.2 to ParaView
// 6.1 with VTK 9.6) differ in API or behaviour, in one place. Everything else in the project is
// the same source on every version.
#ifndef vtkRGCompatibility_h
#define vtkRGCompatibility_h

#include "vtkVersion.h" // VTK_VERSION_NUMBER, VTK_VERSION_CHECK

// vtkWindowedSincPolyDataFilter::SetWindowFunction, whose default became the Nuttall window:
// VTK's master of 2024-03-14 (so ParaView 5.13's VTK 9.3.20240617), first released in VTK 9.4.
// Before it, the window was Hamming, with no setting.
#define RGMC_VTK_SINC_HAS_WINDOW_FUNCTION (VTK_VERSION_NUMBER >= VTK_VERSION_CHECK(9, 3, 20240314))

namespace rgmc
{
/// The start of a filter's run: an abort of an earlier run does not carry over. VTK 9.2 cleared
/// the flag itself; VTK 9.3 and later keep it, so an aborted filter would stay empty. Called from
/// RequestData as `rgmc::ForgetEarlierAbort(this->AbortExecute)` (a protected member, a
/// vtkTypeBool or a std::atomic of one, depending on the version): set directly, as
/// SetAbortExecute would mark the filter modified and make it run again.
template <typename Flag>
void ForgetEarlierAbort(Flag& abortExecute)
{
  abortExecute = 0;
}
} // namespace rgmc

#endif
// VTK-HeaderTest-Exclude: vtkRGCompatibility.h
