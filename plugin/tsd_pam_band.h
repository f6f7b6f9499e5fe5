/*
 * tsd_pam_band.h - the base of a product's bands and an atlas's: their
 * nodata value, unit and colour interpretation are the product's own
 * unless the user set one through PAM (gdal_edit.py -a_nodata, -units,
 * -colorinterp_N; SetNoDataValue...), kept in the .aux.xml; then the
 * user's, as GDAL's read-only drivers report what PAM holds.
 */
#ifndef TSD_PAM_BAND_H
#define TSD_PAM_BAND_H

#include <string>

#include "gdal_pam.h"

namespace tsd
{

class TSPamBand : public GDALPamRasterBand
{
    bool Accepts(const char *pszWhat);

  protected:
    /* what the product says, whatever the user set */
    virtual double OwnNoData() const = 0;
    virtual const char *OwnUnit() const
    {
        return "";
    }
    virtual GDALColorInterp OwnColor() const
    {
        return GCI_GrayIndex;
    }
    /* where the user's settings are: this band's PAM (null while it holds
     * nothing); an overview level's band reads its full-resolution band's */
    virtual const GDALRasterBandPamInfo *UserPam()
    {
        return GetPamInfo();
    }
    /* null, or why what the user sets on this band would not be
     * reported, saying where to set it instead (an overview level) */
    virtual const char *NotHere() const
    {
        return nullptr;
    }

  public:
    double GetNoDataValue(int *pbSuccess = nullptr) override;
    const char *GetUnitType() override;
    GDALColorInterp GetColorInterpretation() override;
    /* none (0 and 1) unless the user set one; a level reports its
     * full-resolution band's */
    double GetOffset(int *pbSuccess = nullptr) override;
    double GetScale(int *pbSuccess = nullptr) override;
    /* refused where NotHere says so */
    CPLErr SetNoDataValue(double dfValue) override;
    CPLErr SetUnitType(const char *pszUnit) override;
    CPLErr SetColorInterpretation(GDALColorInterp eColor) override;
    CPLErr SetOffset(double dfOffset) override;
    CPLErr SetScale(double dfScale) override;
    /* drops a value the user set; the product's own cannot be dropped */
    CPLErr DeleteNoDataValue() override;
    /* drops the statistics and histograms PAM holds (saved for contents
     * the product's files no longer have), keeping what the user set;
     * whether there were any */
    bool DropSavedStatistics();
};

/* The stamp (tsd_source_stamp.h) of the files a dataset's statistics are
 * of, kept beside them in its entry: band 1's PAM metadata item
 * SOURCE_FILES, domain TERRASHADE_PAM. StampPamEntry sets it (before a
 * save: setting it marks nothing dirty that was not); DropStaleStatistics
 * drops every band's saved statistics and histograms where the entry's
 * stamp is missing or not osStamp, and says whether it dropped any. The
 * bands must be TSPamBands. */
void StampPamEntry(GDALPamDataset *poDS, const std::string &osStamp);
bool DropStaleStatistics(GDALPamDataset *poDS, const std::string &osStamp);

} // namespace tsd

#endif
