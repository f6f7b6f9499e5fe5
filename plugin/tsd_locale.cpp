/* tsd_locale.cpp - tsd::CLocale; see tsd_locale.h. */
#include "tsd_locale.h"

#include "tsd_text.h"

namespace tsd
{

CLocale::CLocale() : m_old((locale_t)0)
{
    const locale_t c = tsd_c_locale();
    if (c != (locale_t)0) /* (out of memory: the thread keeps its locale) */
        m_old = uselocale(c);
}

CLocale::~CLocale()
{
    if (m_old != (locale_t)0)
        uselocale(m_old);
}

} // namespace tsd
