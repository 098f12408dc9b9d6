// The windowed-sinc filter's coefficients.
#include "rgmcSmoothing.h"

namespace rgmc
{

std::vector<double> SincCoefficients(int iterations, double passBand, SincWindow window)
{
  const double pi = 3.14159265358979323846;
  const int n = iterations;
  std::vector<double> c(static_cast<std::size_t>(n) + 1, 0.0), w(c.size()), cprime(c.size());
  const double kpb = passBand;
  const double thetaPb = std::acos(1.0 - 0.5 * kpb);
  const double m = static_cast<double>(n + 1);
  for (int i = 0; i <= n; ++i)
  {
    const double x = static_cast<double>(i);
    w[i] = window == SincWindow::Hamming ? 0.54 + 0.46 * std::cos(x * pi / m)
                                         : 0.355768 + 0.487396 * std::cos(x * pi / m) +
        0.144232 * std::cos(2.0 * x * pi / m) + 0.012604 * std::cos(3.0 * x * pi / m);
  }
  // Newton-Raphson on sigma so that the filter's transfer function is 1 at the pass band.
  double sigma = 0.0, f = 0.0;
  bool done = false;
  for (int j = 0; !done && j < 500; ++j)
  {
    c[0] = w[0] * (thetaPb + sigma) / pi;
    for (int i = 1; i <= n; ++i)
    {
      c[i] = 2.0 * w[i] * std::sin(static_cast<double>(i) * (thetaPb + sigma)) /
        (static_cast<double>(i) * pi);
    }
    cprime[n] = 0.0;
    if (n >= 1)
    {
      cprime[n - 1] = 0.0;
    }
    if (n > 1)
    {
      cprime[n - 2] = 2.0 * (n - 1) * c[n - 1];
    }
    for (int i = n - 3; i >= 0; --i)
    {
      cprime[i] = cprime[i + 2] + 2.0 * (i + 1) * c[i + 1];
    }
    f = c[0];
    double fprime = cprime[0];
    for (int i = 1; i <= n; ++i)
    {
      const double t =
        i == 1 ? 1.0 - 0.5 * kpb : std::cos(static_cast<double>(i) * std::acos(1.0 - 0.5 * kpb));
      f += c[i] * t;
      fprime += cprime[i] * t;
    }
    if (n > 1)
    {
      if (std::fabs(f - 1.0) >= 1e-3)
      {
        sigma -= (f - 1.0) / fprime;
      }
      else
      {
        done = true;
      }
    }
    else
    {
      done = true; // a first-order filter cannot be adjusted
      sigma = 0.0;
    }
  }
  return c;
}

} // namespace rgmc
