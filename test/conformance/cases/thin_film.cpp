#include "thin_film.h"

static complex FilmPhase(float eta, float cosTheta, float thickness, float lambda)
{
  const float phase = 4 * M_PI * eta * cosTheta * thickness / lambda;
  return complex(std::cos(phase), std::sin(phase));
}

void ThinFilm::Reflectance(int n, const float* a_cosTheta, float* a_out) { kernel1D_Reflectance(n, a_cosTheta, a_out); }

void ThinFilm::kernel1D_Reflectance(int n, const float* a_cosTheta, float* a_out)
{
  for (int i = 0; i < n; i++)
  {
    const float c = a_cosTheta[i];
    const complex r12 = complex((c - m_eta) / (c + m_eta));
    const complex r23 = 0.5f * r12;
    const complex e = FilmPhase(m_eta, c, m_thickness, m_lambda);
    const complex num = r12 + r23 * e;
    const complex den = complex(1.0f) + r12 * r23 * e;
    const complex r = num / den;
    a_out[i] = complex_norm(r) + real(r) * 0.0f;
  }
}
