/**
 * @class pqRGSeedPointsPropertyWidget
 * @brief The seed list of Region-Growing Marching Cubes, with a handle in the render view to
 * place seeds.
 *
 * The panel widget for the property group that holds `SeedPoints` (and `Input`, whose bounds
 * place the handle). It shows the seeds as an editable table (x, y, z per row) and a handle in
 * the active render view: drag it, type its position, press `P` over a slice or surface to drop
 * it on the surface under the mouse, or `Ctrl+P` to snap it to the nearest mesh point; then
 * "Add Seed" appends its position to the table. The handle is only a pointer: moving it does
 * not change the filter (the Apply button lights up when the table changes, not when the handle
 * moves). Selecting a row moves the handle to that seed.
 *
 * The Python API is unchanged: `SeedPoints=[x0, y0, z0, x1, y1, z1, ...]`.
 */
#ifndef pqRGSeedPointsPropertyWidget_h
#define pqRGSeedPointsPropertyWidget_h

#include "pqInteractivePropertyWidgetAbstract.h"

#include "vtkBoundingBox.h"
#include "vtkSmartPointer.h"

#include <QList>
#include <QVariant>

#include <memory>

class QTableWidget;
class pqDoubleLineEdit;
class vtkSMNewWidgetRepresentationProxy;
namespace Ui
{
class RGSeedPointsWidget;
}

class pqRGSeedPointsPropertyWidget : public pqInteractivePropertyWidgetAbstract
{
  Q_OBJECT
  Q_PROPERTY(
    QList<QVariant> seedPoints READ seedPoints WRITE setSeedPoints NOTIFY seedPointsChanged)
  using Superclass = pqInteractivePropertyWidgetAbstract;

public:
  pqRGSeedPointsPropertyWidget(
    vtkSMProxy* proxy, vtkSMPropertyGroup* group, QWidget* parent = nullptr);
  ~pqRGSeedPointsPropertyWidget() override;

  ///@{
  /// The seeds as a flat list x0, y0, z0, x1, ... (the value of SeedPoints).
  QList<QVariant> seedPoints() const;
  void setSeedPoints(const QList<QVariant>& values);
  ///@}

  /// The handle's position in world coordinates.
  void handlePosition(double position[3]) const;

public Q_SLOTS:
  /// Appends the handle's position to the seeds.
  void addSeedAtHandle();
  /// Removes the selected rows of the table.
  void removeSelectedSeeds();
  /// Removes every seed.
  void removeAllSeeds();
  /// Moves the handle to the centre of the input's bounds.
  void centerOnBounds();
  /// Moves the handle (used by the pickers and the position fields).
  void setHandlePosition(double x, double y, double z);

Q_SIGNALS:
  void seedPointsChanged();

protected Q_SLOTS:
  void placeWidget() override;

protected:
  vtkSMNewWidgetRepresentationProxyAbstract* internalWidgetProxy() override;

private Q_SLOTS:
  void handlePositionTyped();
  void handleMoved();
  void tableEdited();
  void seedSelected();

private:
  Q_DISABLE_COPY(pqRGSeedPointsPropertyWidget)

  void createHandle(vtkSMProxy* proxy);
  void connectControls();
  void showHandlePosition();
  vtkBoundingBox inputBounds();

  vtkSmartPointer<vtkSMNewWidgetRepresentationProxy> Handle;
  std::unique_ptr<Ui::RGSeedPointsWidget> Form; // the form: pqRGSeedPointsPropertyWidget.ui
  QTableWidget* Table = nullptr;
  pqDoubleLineEdit* Position[3] = { nullptr, nullptr, nullptr };
  bool Updating = false;
  bool Placed = false;
};

#endif
