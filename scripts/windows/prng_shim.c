/* bcryptprimitives.dll for Wine 8, which lacks ProcessPrng: Rust's standard library
 * (1.78 and later) imports it for its random numbers, so without it every .exe exits at
 * once with code 53. This one forwards to RtlGenRandom (advapi32's SystemFunction036),
 * which Wine has. Built with mingw into a private Wine prefix by wine_env.sh; never
 * shipped (Windows has ProcessPrng). */
#include <windows.h>

BOOLEAN WINAPI SystemFunction036(PVOID buffer, ULONG length);

BOOL WINAPI ProcessPrng(PBYTE data, SIZE_T length)
{
    while (length > 0) {
        ULONG chunk = length > 0x40000000 ? 0x40000000 : (ULONG)length;
        if (!SystemFunction036(data, chunk)) {
            return FALSE;
        }
        data += chunk;
        length -= chunk;
    }
    return TRUE;
}
