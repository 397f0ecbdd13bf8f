"""facsim studio: the browser workbench (a web server and one page)."""
