"""What every command's job shares: its errors (``errors``), its config file as a TOML document
(``document``) and the typed checks of its values (``schema``), the optional dependencies it
needs (``extras``), its output directory and lock (``output/``), atomic writes (``atomic``),
signals held while files are written (``signals``) and tables as CSV or markdown
(``table_formats``).
"""
