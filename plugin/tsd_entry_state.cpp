/* tsd_entry_state.cpp - tsd::EntryState; see tsd_entry_state.h. */
#include "tsd_entry_state.h"

#include "tsd_text.h"

namespace tsd
{

EntryState::EntryState() : m_old((locale_t)0), m_fenv(), m_bFenv(false)
{
    const locale_t c = tsd_c_locale();
    if (c != (locale_t)0) /* (out of memory: the thread keeps its locale) */
        m_old = uselocale(c);
    /* feholdexcept: saved, flags cleared, every trap off */
    m_bFenv = feholdexcept(&m_fenv) == 0;
    if (m_bFenv)
        fesetround(FE_TONEAREST);
}

EntryState::~EntryState()
{
    if (m_bFenv)
        fesetenv(&m_fenv);
    if (m_old != (locale_t)0)
        uselocale(m_old);
}

} // namespace tsd
