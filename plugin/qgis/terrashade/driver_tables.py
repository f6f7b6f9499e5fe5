"""What the TERRASHADE driver declares about itself, read at run time.

Two metadata items of the loaded driver are the only source of the
provider's algorithms and parameters:

- DMD_OPENOPTIONLIST (GDAL_DMD_OPENOPTIONLIST): every open option with its
  type, default, range, choices and description;
- TERRASHADE_PRODUCTS: the product table, one <Product> per product with its
  description, unit, bands, whether it is a day product, its Byte mapping and
  the open options that apply to it.

Nothing here imports QGIS, so the tests and the GDAL Python console can use it.
"""
import xml.etree.ElementTree as ET
from collections import namedtuple

from osgeo import gdal

DRIVER = "TERRASHADE"
PRODUCTS_ITEM = "TERRASHADE_PRODUCTS"

# kind: "float", "int", "bool", "choice" or "string" (GDAL's XML types mapped);
# default: the declared text, or None; minimum/maximum: floats, or None;
# values: the choices of a "choice".
Option = namedtuple("Option", "name kind default minimum maximum values description")
# bands: the band count with the default options (text); bands_option: the
# option that sets the count, or ""; options: the names of those that apply.
Product = namedtuple("Product", "name description unit bands bands_option daily byte "
                     "options")

_KINDS = {"float": "float", "real": "float", "int": "int", "integer": "int",
          "boolean": "bool", "string-select": "choice", "string": "string"}


class DriverError(Exception):
    """The driver is not loaded, or does not describe itself as expected."""


def _number(text):
    return None if text is None or text == "" else float(text)


def parse_options(xml_text):
    """{name: Option} from the driver's <OpenOptionList> XML, in its order."""
    options = {}
    for el in ET.fromstring(xml_text).iter("Option"):
        kind = _KINDS.get(el.get("type", "string"))
        if kind is None:
            raise DriverError("option %s has a type this provider does not know: %s"
                              % (el.get("name"), el.get("type")))
        options[el.get("name")] = Option(
            el.get("name"), kind, el.get("default"), _number(el.get("min")),
            _number(el.get("max")), [v.text for v in el.iter("Value")],
            el.get("description", ""))
    return options


def is_yes(text):
    """GDAL's reading of a boolean option's text."""
    return (text or "").strip().lower() in ("yes", "true", "on", "1")


def parse_products(xml_text):
    """[Product] from the driver's <Products> XML, in its order."""
    products = []
    for el in ET.fromstring(xml_text).iter("Product"):
        names = [n.strip() for n in el.get("options", "").split(",") if n.strip()]
        products.append(Product(el.get("name"), el.get("description", ""),
                                el.get("unit", ""), el.get("bands", ""),
                                el.get("bands_option", ""), is_yes(el.get("daily")),
                                el.get("byte", "never"), names))
    return products


def single_raster(product):
    """True for a product that is one raster, not a time series.

    A day product whose band count follows an option (one band per time step
    or per sun position: daycycle with STEP_MINUTES, farshadow with
    ATLAS_STEPS) is a series of hundreds of bands, or an atlas file, and stays
    with gdal_translate. Elsewhere such an option is the user's choice of
    bands (horizon: DIRECTIONS), and a day product with a fixed count is one
    raster (sunhours, insolation).
    """
    return not (product.daily and product.bands_option)


def read_driver():
    """(options, products) of the loaded driver; DriverError says what is wrong."""
    drv = gdal.GetDriverByName(DRIVER)
    if drv is None:
        raise DriverError(
            "The TERRASHADE GDAL driver is not loaded. Install gdal_TERRASHADE.so into "
            "GDAL's plugin folder (make install), or start QGIS with GDAL_DRIVER_PATH "
            "set to the folder that holds it.")
    option_xml = drv.GetMetadataItem("DMD_OPENOPTIONLIST")
    product_xml = drv.GetMetadataItem(PRODUCTS_ITEM)
    if not option_xml or not product_xml:
        raise DriverError(
            "The TERRASHADE driver GDAL loaded does not list its %s: it is older than "
            "this QGIS plugin. Install both from the same terrashade version."
            % ("open options" if not option_xml else "products (" + PRODUCTS_ITEM + ")"))
    try:
        options, products = parse_options(option_xml), parse_products(product_xml)
    except ET.ParseError as e:
        raise DriverError("The TERRASHADE driver's metadata is not valid XML: %s" % e)
    for p in products:
        unknown = [n for n in p.options if n not in options]
        if unknown:
            raise DriverError("The TERRASHADE driver lists option(s) %s for product %s "
                              "but does not declare them." % (", ".join(unknown), p.name))
    return options, products
