/*
** The conifit version, written into every output file that records its provenance.
** conifit-layer: base
*/
#ifndef CF_VERSION_H
#define CF_VERSION_H

#define CF_VERSION "0.1.0"

#endif
